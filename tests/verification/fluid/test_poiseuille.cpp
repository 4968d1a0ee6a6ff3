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
  s.viscosity_pa_s = 1.0;                      // nu = 1 m^2/s
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

namespace boycott::fluid {
namespace {

/// Start-up of plane Poiseuille flow from rest (W = 1, nu = 1, g = 8):
/// w(y, t) = 4 y (1 - y) - sum_{n odd} 32 / (n pi)^3 sin(n pi y) exp(-(n pi)^2 t).
double startup_exact(double y, double t) {
  double w = 4.0 * y * (1.0 - y);
  for (int n = 1; n < 400; n += 2) {
    const double a = n * M_PI;
    w -= 32.0 / (a * a * a) * std::sin(a * y) * std::exp(-a * a * t);
  }
  return w;
}

std::vector<double> startup_profile(int ny, double dt, double t_end) {
  FluidSettings s = channel(ny, dt);
  s.simple_tolerance = 1e-12;
  s.simple_max_iterations = 200;
  FluidSolver f(s);
  const int steps = static_cast<int>(std::lround(t_end / dt));
  for (int n = 0; n < steps; ++n) f.step(dt);
  return f.profile_y(2);
}

TEST(PoiseuilleStartup, FollowsSeriesSolutionAtSeveralTimes) {
  // 24 cells across: steady spatial error 0.17 % of the centreline; dt = 1/800 W^2/nu.
  const int ny = 24;
  FluidSettings s = channel(ny, 1.25e-3);
  s.simple_tolerance = 1e-10;
  s.simple_max_iterations = 100;
  FluidSolver f(s);
  for (double t_check : {0.02, 0.05, 0.1, 0.3}) {
    while (f.time_s() < t_check - 1e-9) f.step(1.25e-3);
    const auto w = f.profile_y(2);
    double err = 0.0;
    for (int j = 0; j < ny; ++j)
      err = std::max(err, std::abs(w[j] - startup_exact((j + 0.5) / ny, f.time_s())));
    std::printf("t = %.3f: max error / centreline %.3g\n", f.time_s(), err);
    EXPECT_LE(err, 0.003) << "t = " << t_check;
  }
}

TEST(PoiseuilleStartup, SecondOrderInTime) {
  // Fixed grid; the temporal error e(dt) = |w_dt - w_dt/2| shrinks 4x per halving for BDF2.
  const int ny = 12;
  const double t_end = 0.1;
  const auto a = startup_profile(ny, 0.01, t_end), b = startup_profile(ny, 0.005, t_end),
             c = startup_profile(ny, 0.0025, t_end);
  double e1 = 0.0, e2 = 0.0;
  for (int j = 0; j < ny; ++j)
    e1 = std::max(e1, std::abs(a[j] - b[j])), e2 = std::max(e2, std::abs(b[j] - c[j]));
  const double order = std::log2(e1 / e2);
  std::printf("temporal differences %.3g %.3g, observed order %.3f\n", e1, e2, order);
  EXPECT_GE(order, 1.8);
}

}  // namespace
}  // namespace boycott::fluid
