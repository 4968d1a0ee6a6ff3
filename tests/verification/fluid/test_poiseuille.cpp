// Plane Poiseuille flow between the y walls driven by a z body force (steady and start-up).
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/fluid_solver.hpp"

namespace boycott::fluid {
namespace {

FluidSettings channel(int ny, double dt) {
  FluidSettings s;
  s.grid.n = {4, ny, 4};
  s.grid.length_m = {4.0, 1.0, 4.0};  // W = 1 m
  s.grid.periodic = {true, false, true};
  s.density_kg_m3 = 1.0;
  s.viscosity_pa_s = 1.0;  // nu = 1 m^2/s
  s.body_acceleration_m_s2 = {0.0, 0.0, 8.0};  // centreline g W^2 / (8 nu) = 1 m/s
  s.dt_max_s = dt;
  s.simple_tolerance = 1e-10;
  s.simple_max_iterations = 60;
  return s;
}

/// max |w - w_exact| / w_centre over the y cells, steady state reached by time stepping.
double steady_error(int ny) {
  FluidSolver f(channel(ny, 0.05));
  for (int n = 0; n < 120; ++n) f.step(f.stable_dt());
  const auto w = f.profile_y(2);
  double err = 0.0;
  for (int j = 0; j < ny; ++j) {
    const double y = (j + 0.5) / ny;
    err = std::max(err, std::abs(w[j] - 4.0 * y * (1.0 - y)));
  }
  return err;
}

TEST(PlanePoiseuille, SixCellsWithinThreePercent) {
  const double e6 = steady_error(6);
  std::printf("max error / centreline, 6 cells: %.4g\n", e6);
  EXPECT_LE(e6, 0.03);
}

TEST(PlanePoiseuille, ConvergesAtSecondOrder) {
  const double e6 = steady_error(6), e12 = steady_error(12), e24 = steady_error(24);
  const double order = std::log(e6 / e24) / std::log(4.0);
  std::printf("errors %.4g %.4g %.4g, observed order %.3f\n", e6, e12, e24, order);
  EXPECT_GE(order, 1.9);
}

}  // namespace
}  // namespace boycott::fluid
