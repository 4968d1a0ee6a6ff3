// DistributedSpectralPoisson (x and y on z-slabs, z after an all-to-all) gives what the serial
// SpectralPoissonPreconditioner gives on the whole vector, to round-off, for walls or periodicity
// in y and odd sizes. Run under `mpirun -n 2` or `-n 3` (also correct on one rank).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <random>
#include <vector>

#include "fluid/spectral_poisson_pc.hpp"

namespace {
using boycott::fluid::DistributedSpectralPoisson;
using boycott::fluid::SpectralPoissonPreconditioner;

double worst_difference(int nx, int ny, int nz, bool periodic_y) {
  const double c[3] = {2.5e4, 1.1e6, 4.0e4};  // anisotropic cells, 1/m^2
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> r(static_cast<std::size_t>(nx) * ny * nz), z(r.size());
  for (double& v : r) v = u(rng);  // the same on every rank
  SpectralPoissonPreconditioner serial(nx, ny, nz, periodic_y);
  serial.set_coefficients(c[0], c[1], c[2]);
  serial.apply(r.data(), z.data());

  DistributedSpectralPoisson dist(nx, ny, nz, periodic_y, MPI_COMM_WORLD);
  dist.set_coefficients(c[0], c[1], c[2]);
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  const std::size_t first = plane * dist.z_begin(), count = plane * dist.z_count();
  std::vector<double> zs(count + 1);
  dist.apply(r.data() + first, zs.data());
  int covered = dist.z_count(), total = 0;
  MPI_Allreduce(&covered, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, nz) << "the slabs do not cover the z planes";
  double diff = 0.0, ref = 0.0;
  for (std::size_t q = 0; q < count; ++q) diff = std::max(diff, std::abs(zs[q] - z[first + q]));
  for (double v : z) ref = std::max(ref, std::abs(v));
  double worst = 0.0;
  MPI_Allreduce(&diff, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return worst / ref;
}

TEST(DistributedSpectralPoisson, MatchesTheSerialTransformWithWalls) {
  const double d = worst_difference(20, 6, 10, false);
  std::printf("max |distributed - serial| / max |z| = %.3g\n", d);
  EXPECT_LE(d, 1e-12);
}

TEST(DistributedSpectralPoisson, MatchesTheSerialTransformPeriodicAndOdd) {
  const double d = worst_difference(9, 5, 7, true);
  std::printf("max |distributed - serial| / max |z| = %.3g\n", d);
  EXPECT_LE(d, 1e-12);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int rc = RUN_ALL_TESTS();
  MPI_Finalize();
  return rc;
}
