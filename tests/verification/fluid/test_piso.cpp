// PISO (numerics.pressure_velocity_coupling = "piso") beside SIMPLE: the same analytic checks as
// SIMPLE's (Taylor-Green decay, steady Poiseuille, second order in time), continuity after the
// last corrector with a moving fluid fraction, the flux controller, and its difference from a
// SIMPLE run iterated to convergence on the same problem.
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/fluid_solver.hpp"
#include "tests/verification/fluid/fluid_cases.hpp"

namespace boycott::fluid {
namespace {

FluidSettings piso(FluidSettings s) {
  s.piso = true;
  s.piso_correctors = 2;
  return s;
}

// tighter SIMPLE tolerances than the Taylor-Green and channel tests: SIMPLE is the reference here
FluidSettings taylor_green(int n, double dt, double nu) {
  FluidSettings s = testing::taylor_green_settings(n, dt, nu);
  s.simple_tolerance = 1e-11;
  s.simple_max_iterations = 200;
  return s;
}
using testing::init_taylor_green;
using testing::kinetic_energy;

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

FluidSettings wavy_channel() {
  FluidSettings s = testing::wavy_channel();
  s.simple_tolerance = 1e-11;
  s.simple_max_iterations = 200;
  return s;
}

auto moving_alpha(double t) {
  return [=](double x, double y, double z) {
    return 0.7 + 0.2 * std::sin(M_PI * x - 20.0 * t) * std::cos(M_PI * z) * (0.5 + y);
  };
}

/// Runs the wavy channel to t = 0.1 s; returns u, v, w and the worst continuity defect (1/s).
std::pair<std::vector<std::vector<double>>, double> run_wavy(const FluidSettings& s, double dt) {
  FluidSolver f(s);
  testing::perturb_wavy_channel(f);
  f.set_fluid_fraction(moving_alpha(0.0));
  double worst = 0.0;
  const int steps = static_cast<int>(std::lround(0.1 / dt));
  for (int n = 1; n <= steps; ++n) {
    f.set_fluid_fraction(moving_alpha(n * dt));
    f.step(dt);
    worst = std::max(worst, f.max_continuity_defect());
  }
  return {{f.gather(0), f.gather(1), f.gather(2)}, worst};
}

TEST(PisoCoupling, TaylorGreenDecayRateWithinOnePercent) {
  // As TaylorGreenVortex.DecayRateWithinOnePercent (32 x 32, Re 126, dt 0.02 s, CFL 0.1).
  const double nu = 0.05;
  FluidSolver f(piso(taylor_green(32, 0.02, nu)));
  init_taylor_green(f);
  f.step(0.02);
  const double t1 = f.time_s(), e1 = kinetic_energy(f);
  while (f.time_s() < 1.0 - 1e-9) f.step(0.02);
  const double rate = std::log(e1 / kinetic_energy(f)) / (f.time_s() - t1);
  std::printf("PISO energy decay rate %.6f, exact %.6f (rel. error %.3g)\n", rate, 4.0 * nu,
              rate / (4.0 * nu) - 1.0);
  EXPECT_NEAR(rate / (4.0 * nu), 1.0, 0.01);
}

TEST(PisoCoupling, SecondOrderInTimeOnTaylorGreen) {
  // Fixed 16 x 16 grid at Re 126 (convection and pressure both matter); e(dt) = max|u_dt -
  // u_dt/2| at t = 0.48 s must fall 4x per halving. SIMPLE's differences are printed beside.
  const double nu = 0.05, t_end = 0.48;
  auto run = [&](bool use_piso, double dt) {
    FluidSettings s = taylor_green(16, dt, nu);
    if (use_piso) s = piso(s);
    FluidSolver f(s);
    init_taylor_green(f);
    const int steps = static_cast<int>(std::lround(t_end / dt));
    for (int n = 0; n < steps; ++n) f.step(dt);
    return f.gather(0);
  };
  for (bool use_piso : {false, true}) {
    const auto a = run(use_piso, 0.04), b = run(use_piso, 0.02), c = run(use_piso, 0.01);
    const double e1 = max_diff(a, b), e2 = max_diff(b, c), order = std::log2(e1 / e2);
    std::printf("%s: temporal differences %.3g %.3g, observed order %.3f\n", use_piso ? "PISO" : "SIMPLE", e1,
                e2, order);
    if (use_piso) {
      EXPECT_GE(order, 1.8);
    }
  }
}

TEST(PisoCoupling, SteadyPoiseuilleIsSimplesFixedPoint) {
  // Steady flow is a fixed point of both schemes: PISO must land on SIMPLE's 6-cell profile
  // (3 % from the parabola, PlanePoiseuille.SixCellsWithinThreePercent).
  FluidSettings s;
  s.grid.n = {4, 6, 4};
  s.grid.length_m = {4.0, 1.0, 4.0};
  s.grid.periodic = {true, false, true};
  s.density_kg_m3 = 1.0;
  s.viscosity_pa_s = 1.0;
  s.body_acceleration_m_s2 = {0.0, 0.0, 8.0};  // centreline 1 m/s
  s.dt_max_s = 0.05;
  s.simple_tolerance = 1e-10;
  s.simple_max_iterations = 60;
  FluidSolver a(s), b(piso(s));
  for (int n = 0; n < 120; ++n) a.step(0.05), b.step(0.05);
  const auto wa = a.profile_y(2), wb = b.profile_y(2);
  double diff = 0.0, err = 0.0;
  for (int j = 0; j < 6; ++j) {
    const double y = (j + 0.5) / 6;
    diff = std::max(diff, std::abs(wa[j] - wb[j]));
    err = std::max(err, std::abs(wb[j] - 4.0 * y * (1.0 - y)));
  }
  std::printf("PISO: max error / centreline %.4g; max |PISO - SIMPLE| %.3g\n", err, diff);
  EXPECT_LE(err, 0.03);
  // PISO solves each momentum equation once per step, to the momentum KSP's rtol 1e-8 of |b|
  // (SIMPLE's repeated solves converge further): 1.5e-8 here, 2e-12 with -momentum_ksp_rtol 1e-12.
  EXPECT_LE(diff, 1e-7);
}

TEST(PisoCoupling, MovingFluidFractionStaysCloseToSimpleAndConservesVolume) {
  // The wavy channel with alpha_f moving at |d alpha/dt| up to 6 1/s, to t = 0.1 s. PISO is not
  // iterated, so it differs from converged SIMPLE by its splitting error; that difference must
  // be second order in dt and, at dt = 0.01 s, below SIMPLE's own time-step error (the
  // difference between SIMPLE at dt and dt/2). After the last corrector the continuity defect
  // is what the pressure solve leaves (rtol 1e-3 of a defect that is itself O(dt^2)).
  const auto simple1 = run_wavy(wavy_channel(), 0.01), simple2 = run_wavy(wavy_channel(), 0.005);
  const auto piso1 = run_wavy(piso(wavy_channel()), 0.01), piso2 = run_wavy(piso(wavy_channel()), 0.005);
  double d1 = 0.0, d2 = 0.0, dt_err = 0.0, ref = 0.0;
  for (int c = 0; c < 3; ++c) {
    d1 = std::max(d1, max_diff(piso1.first[c], simple1.first[c]));
    d2 = std::max(d2, max_diff(piso2.first[c], simple2.first[c]));
    dt_err = std::max(dt_err, max_diff(simple1.first[c], simple2.first[c]));
    for (double v : simple1.first[c]) ref = std::max(ref, std::abs(v));
  }
  std::printf(
      "max |PISO - SIMPLE| / max|u|: dt 0.01 %.3g, dt 0.005 %.3g (order %.2f); SIMPLE dt vs dt/2 %.3g\n",
      d1 / ref, d2 / ref, std::log2(d1 / d2), dt_err / ref);
  std::printf("worst continuity defect: PISO %.3g 1/s, SIMPLE %.3g 1/s\n", piso1.second, simple1.second);
  EXPECT_GE(std::log2(d1 / d2), 1.8);
  EXPECT_LE(d1, dt_err);
  EXPECT_LE(piso1.second, 1e-3);
}

TEST(PisoCoupling, FluxControllerHoldsTarget) {
  const double worst =
      testing::hold_flux_against_opposing_body_force(piso(wavy_channel())).worst_relative_error;
  std::printf("PISO: worst relative flux error %.3g\n", worst);
  EXPECT_LE(worst, 1e-6);
}

}  // namespace
}  // namespace boycott::fluid
