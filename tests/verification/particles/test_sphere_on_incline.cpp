// A sphere on a plane wall with gravity inclined at theta, and a spinning pair: the rolling
// friction (Eq. 11) and Coulomb friction (Eq. 10) against rigid-body mechanics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dem_test_util.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

namespace {
constexpr double kG = 9.81, kMu = 0.6, kMuR = 0.1;

struct InclineRun {
  double accel_m_s2;      ///< mean acceleration along the slope over [t1, t2]
  double displacement_m;  ///< distance travelled along the slope over [t1, t2]
  double max_speed_m_s;   ///< largest |v| over [t1, t2]
};

/// The wall y = 0 is the plane; gravity (0, -g cos th, -g sin th) pulls down the slope (-z).
InclineRun run_incline(double tan_theta, double t1, double t2) {
  const double th = std::atan(tan_theta);
  auto cfg = make_config(20 * kD, true, 0.1, kMu, kMuR, 20e-6);
  cfg.gravity_m_s2 = {0.0, -kG * std::cos(th), -kG * std::sin(th)};
  DemSystem dem(cfg);
  const double delta_eq = particle_mass() * kG * std::cos(th) / kKn;
  dem.add_particle(0, 10 * kD, kR - delta_eq, 10 * kD, kR, kRho);
  dem.initialize();
  auto& s = dem.particles();
  double z1 = 0, v1 = 0, vmax = 0;
  const auto n1 = std::llround(t1 / cfg.dt_s), n2 = std::llround(t2 / cfg.dt_s);
  double zun = s.z[0], zprev = s.z[0];  // unwrapped z across the periodic boundary
  for (long long n = 1; n <= n2; ++n) {
    dem.step();
    double dz = s.z[0] - zprev;
    if (dz > 5 * kD) dz -= cfg.box.len[2];
    if (dz < -5 * kD) dz += cfg.box.len[2];
    zun += dz;
    zprev = s.z[0];
    if (n == n1) {
      z1 = zun;
      v1 = s.vz[0];
    }
    if (n >= n1) vmax = std::max(vmax, std::sqrt(s.vx[0] * s.vx[0] + s.vy[0] * s.vy[0] + s.vz[0] * s.vz[0]));
  }
  return {-(s.vz[0] - v1) / (t2 - t1), -(zun - z1), vmax};
}
}  // namespace

TEST(SphereOnIncline, StaysAtRestBelowRollingFriction) {
  // tan(theta) = 0.05 < mu_r = 0.1: the rolling torque can hold the sphere.
  const auto r = run_incline(0.05, 0.1, 0.6);
  std::printf("[ report ] tan th = 0.05: displacement %.3e m, max speed %.3e m/s over 0.5 s\n",
              r.displacement_m, r.max_speed_m_s);
  // At rest: over 0.5 s it moves less than 1e-3 of a diameter (it would roll 1.6e-1 m at the
  // rolling acceleration of tan th = 0.5 in the same time).
  EXPECT_LT(std::abs(r.displacement_m), 1e-3 * kD);
  EXPECT_LT(r.max_speed_m_s, 1e-5);
}

TEST(SphereOnIncline, RollsWithoutSlippingBetweenTheLimits) {
  // mu_r < tan th = 0.5 < (7/2)(mu - mu_r) + mu_r = 1.85: a = (5/7) g (sin th - mu_r cos th).
  const double th = std::atan(0.5);
  const double expect = 5.0 / 7.0 * kG * (std::sin(th) - kMuR * std::cos(th));
  const auto r = run_incline(0.5, 0.1, 0.3);
  EXPECT_NEAR(r.accel_m_s2, expect, 0.01 * expect);
}

TEST(SphereOnIncline, SlidesAboveTheRollingLimit) {
  // tan th = 2.5 > 1.85: the contact slides, a = g (sin th - mu cos th).
  const double th = std::atan(2.5);
  const double expect = kG * (std::sin(th) - kMu * std::cos(th));
  const auto r = run_incline(2.5, 0.1, 0.2);
  EXPECT_NEAR(r.accel_m_s2, expect, 0.01 * expect);
}

TEST(RollingFriction, SpinningPairDeceleratesAtEq11Rate) {
  // Two spheres pressed together along x by F0 and spun in opposite senses about z: their surfaces
  // roll on each other without slip, so only the rolling torque acts:
  // I dw/dt = -mu_r F0 R until the relative rotation stops, then it stays stopped (no chatter).
  const double F0 = 1e-4;  // N
  DemSystem dem(make_config(20 * kD, false, 0.1, kMu, kMuR, 20e-6));
  const double delta = F0 / kKn;
  dem.add_particle(0, 5 * kD, 5 * kD, 5 * kD, kR, kRho);
  dem.add_particle(1, 5 * kD + 2 * kR - delta, 5 * kD, 5 * kD, kR, kRho);
  auto& s = dem.particles();
  const double W0 = 20.0;  // rad/s
  s.ext_x = {F0, -F0};
  s.wz = {W0, -W0};
  dem.initialize();
  const double I = s.inertia[0];
  const double rate = kMuR * F0 * kR / I;  // rad/s^2
  const double t_stop = W0 / rate;
  const auto n_half = std::llround(0.5 * t_stop / 20e-6);
  for (long long n = 0; n < n_half; ++n) dem.step();
  const int i0 = s.id[0] == 0 ? 0 : 1;
  const double expect_half = W0 - rate * dem.time_s();
  EXPECT_NEAR(s.wz[i0], expect_half, 0.01 * W0);
  const double w_half = s.wz[i0];
  for (long long n = 0; n < 2 * n_half; ++n) dem.step();
  EXPECT_LT(std::abs(s.wz[i0]), 1e-3 * W0) << "rotation did not come to rest";
  std::printf(
      "[ report ] spinning pair: w(t_stop/2) = %.4f rad/s (Eq. 11: %.4f), w(1.5 t_stop) = %.2e rad/s\n",
      w_half, expect_half, s.wz[i0]);
}
