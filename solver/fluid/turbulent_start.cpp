#include "fluid/turbulent_start.hpp"

#include <cmath>
#include <random>
#include <vector>

#include "core/constants.hpp"
#include "fluid/fluid_solver.hpp"

namespace boycott::fluid {

void start_turbulent_channel(FluidSolver& f, const TurbulentStartSettings& s) {
  const auto& g = f.settings().grid;
  const double H = g.length_m[1], Lx = g.length_m[0], Lz = g.length_m[2];
  const double floor = s.floor_m, depth = H - floor, z0 = s.roughness_m / 30.0, U = s.bulk_velocity_m_s;
  auto log_law = [&](double y) { return y > floor ? std::log1p((y - floor) / z0) : 0.0; };
  // Mean of the log law over y, midpoint rule fine enough to resolve z0.
  constexpr int kQuadrature = 20000;
  double mean = 0.0;
  for (int j = 0; j < kQuadrature; ++j) mean += log_law((j + 0.5) * H / kQuadrature) / kQuadrature;
  const double scale = mean > 0.0 ? U / mean : 0.0;

  const int n = s.max_wavenumber + 1;
  std::vector<double> phase(static_cast<std::size_t>(3 * n * n * 2));
  std::mt19937_64 rng(s.seed);
  std::uniform_real_distribution<double> uniform_phase(0.0, 2.0 * kPi);
  for (double& ph : phase) ph = uniform_phase(rng);
  const double amp = s.mode_amplitude * U;
  auto perturbation = [&](int c, double x, double y, double z) {
    if (y <= floor) return 0.0;
    const double yc = (y - floor) / depth;
    double sum = 0.0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        if (a == 0 && b == 0) continue;
        const double* ph = &phase[static_cast<std::size_t>(((c * n + a) * n + b) * 2)];
        sum += std::sin(2.0 * kPi * (a * x / Lx + b * z / Lz) + ph[0]) *
               std::sin(2.0 * kPi * (a + b) * yc + ph[1]);
      }
    return amp * sum * std::sin(0.5 * kPi * yc);
  };
  f.set_velocity(0, [&](double x, double y, double z) { return perturbation(0, x, y, z); });
  f.set_velocity(1, [&](double x, double y, double z) { return perturbation(1, x, y, z); });
  f.set_velocity(2,
                 [&](double x, double y, double z) { return scale * log_law(y) + perturbation(2, x, y, z); });
}

}  // namespace boycott::fluid
