// Flows shared by the fluid verification tests: the Taylor-Green vortex in the periodic x-z
// plane and a 3-D channel with walls, convection and pressure ("wavy channel").
#pragma once

#include <algorithm>
#include <cmath>

#include "fluid/fluid_solver.hpp"

namespace boycott::fluid::testing {

/// Taylor-Green vortex on n x 2 x n cells of a 2 pi periodic box (y periodic too, the flow
/// independent of y); U = 1 m/s, rho = 1, so nu = 0.05 m^2/s gives Re = U L / nu = 126.
inline FluidSettings taylor_green_settings(int n, double dt, double nu) {
  FluidSettings s;
  s.grid.n = {n, 2, n};
  s.grid.length_m = {2.0 * M_PI, 2.0 * M_PI / n * 2, 2.0 * M_PI};
  s.grid.periodic = {true, true, true};
  s.density_kg_m3 = 1.0;
  s.viscosity_pa_s = nu;
  s.dt_max_s = dt;
  s.simple_tolerance = 1e-9;
  s.simple_max_iterations = 100;
  return s;
}

/// u = sin x cos z, w = -cos x sin z.
inline void init_taylor_green(FluidSolver& f) {
  f.set_velocity(0, [](double x, double, double z) { return std::sin(x) * std::cos(z); });
  f.set_velocity(1, [](double, double, double) { return 0.0; });
  f.set_velocity(2, [](double x, double, double z) { return -std::cos(x) * std::sin(z); });
}

/// Sum of u^2/2 + w^2/2 over the faces (proportional to the kinetic energy).
inline double kinetic_energy(const FluidSolver& f) {
  double e = 0.0;
  for (int c = 0; c < 3; c += 2)
    for (double v : f.gather(c)) e += 0.5 * v * v;
  return e;
}

/// A 3-D flow with convection, pressure and walls: Poiseuille-driven channel (8 x 6 x 8 cells,
/// 2 x 1 x 2 m) with a Taylor-Green type perturbation in the x-z plane (perturb_wavy_channel).
inline FluidSettings wavy_channel() {
  FluidSettings s;
  s.grid.n = {8, 6, 8};
  s.grid.length_m = {2.0, 1.0, 2.0};
  s.grid.periodic = {true, false, true};
  s.density_kg_m3 = 1.0;
  s.viscosity_pa_s = 0.05;
  s.body_acceleration_m_s2 = {0.0, 0.0, 0.4};
  s.dt_max_s = 0.01;
  s.simple_tolerance = 1e-10;
  s.simple_max_iterations = 100;
  return s;
}

inline void perturb_wavy_channel(FluidSolver& f) {
  f.set_velocity(0, [](double x, double y, double z) {
    return 0.2 * std::sin(M_PI * x) * std::cos(M_PI * z) * y * (1 - y);
  });
  f.set_velocity(2, [](double x, double y, double z) {
    return y * (1 - y) * (1.0 - 0.2 * std::cos(M_PI * x) * std::sin(M_PI * z));
  });
}

/// The flux controller's check: the flow of `s` (the wavy channel) pushed against a target mean
/// flux of 0.05 m/s by an opposing body force, over a non-uniform alpha_f, 40 steps of 0.05 s.
struct FluxHold {
  double worst_relative_error = 0.0;  ///< max over the steps of |mean(a w) / target - 1|
  bool all_converged = true;
};
inline FluxHold hold_flux_against_opposing_body_force(FluidSettings s) {
  s.body_acceleration_m_s2 = {0.0, 0.0, -1.0};  // opposes the target: G must reverse it
  s.target_mean_flux_z_m_s = 0.05;
  s.dt_max_s = 0.05;
  FluidSolver f(s);
  f.set_fluid_fraction(
      [](double x, double, double z) { return 0.8 + 0.1 * std::sin(M_PI * x) * std::cos(M_PI * z); });
  FluxHold h;
  for (int n = 0; n < 40; ++n) {
    h.all_converged = f.step(0.05).converged && h.all_converged;
    h.worst_relative_error = std::max(h.worst_relative_error, std::abs(f.mean_flux_z() / 0.05 - 1.0));
  }
  return h;
}

}  // namespace boycott::fluid::testing
