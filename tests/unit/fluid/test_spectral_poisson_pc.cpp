// SpectralPoissonPreconditioner is the exact (pseudo-)inverse of the constant-coefficient
// 7-point operator it is built for: applying that operator to M^+ r gives r minus its mean, to
// round-off, with walls or periodicity in y, and for a periodic direction only two cells long.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fluid/spectral_poisson_pc.hpp"

namespace {
using boycott::fluid::SpectralPoissonPreconditioner;

// sum over faces of c_d (p_cell - p_neighbour); x, z periodic, y periodic or walls (no flux).
std::vector<double> apply_operator(const std::vector<double>& p, int nx, int ny, int nz, bool periodic_y,
                                   const double c[3]) {
  auto at = [&](int i, int j, int k) {
    i = (i + nx) % nx;
    k = (k + nz) % nz;
    j = (j + ny) % ny;
    return p[static_cast<std::size_t>(i) + nx * (j + static_cast<std::size_t>(ny) * k)];
  };
  std::vector<double> out(p.size());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double pc = at(i, j, k);
        double a = c[0] * (2 * pc - at(i - 1, j, k) - at(i + 1, j, k)) +
                   c[2] * (2 * pc - at(i, j, k - 1) - at(i, j, k + 1));
        if (periodic_y || j > 0) a += c[1] * (pc - at(i, j - 1, k));
        if (periodic_y || j < ny - 1) a += c[1] * (pc - at(i, j + 1, k));
        out[static_cast<std::size_t>(i) + nx * (j + static_cast<std::size_t>(ny) * k)] = a;
      }
  return out;
}

double worst_error(int nx, int ny, int nz, bool periodic_y) {
  const double c[3] = {2.5e4, 1.1e6, 4.0e4};  // anisotropic cells, 1/m^2
  SpectralPoissonPreconditioner pc(nx, ny, nz, periodic_y);
  pc.set_coefficients(c[0], c[1], c[2]);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<double> r(static_cast<std::size_t>(nx) * ny * nz), z(r.size());
  double mean = 0.0, rmax = 0.0;
  for (double& v : r) mean += (v = U(rng));
  mean /= static_cast<double>(r.size());
  pc.apply(r.data(), z.data());
  const auto Az = apply_operator(z, nx, ny, nz, periodic_y, c);
  double err = 0.0, zmean = 0.0;
  for (std::size_t q = 0; q < r.size(); ++q) {
    err = std::max(err, std::abs(Az[q] - (r[q] - mean)));
    rmax = std::max(rmax, std::abs(r[q]));
    zmean += z[q];
  }
  EXPECT_LT(std::abs(zmean) / static_cast<double>(r.size()), 1e-12 * rmax / c[0])
      << "M^+ r keeps a constant part";
  return err / rmax;
}
}  // namespace

TEST(SpectralPoissonPreconditioner, InvertsTheConstantCoefficientOperatorBetweenWalls) {
  EXPECT_LT(worst_error(20, 6, 10, false), 1e-11);
}

TEST(SpectralPoissonPreconditioner, InvertsTheConstantCoefficientOperatorFullyPeriodic) {
  EXPECT_LT(worst_error(12, 8, 10, true), 1e-11);
  EXPECT_LT(worst_error(9, 5, 7, true), 1e-11);  // odd sizes: no Nyquist mode
}

TEST(SpectralPoissonPreconditioner, InvertsWithATwoCellPeriodicDirection) {
  EXPECT_LT(worst_error(2, 6, 8, false), 1e-11);
}
