// The stateless contact kernels of particles/contact_kernels.hpp, called alone: the normal
// spring-dashpot, the tangential spring with its Coulomb cap, and the rolling resistance of
// Eq. 11 for a pair and for a wall (a sphere of infinite inertia).
#include <gtest/gtest.h>

#include <cmath>

#include "core/constants.hpp"
#include "particles/contact_kernels.hpp"

namespace boycott::particles {
namespace {

// Normal force k_n delta - gamma_n v_n (n points into the sphere, v_r = v_i - v_j).
TEST(ContactKernels, NormalForceIsSpringMinusDashpot) {
  const LinearSpringDashpot cm(3.5, 0.1, 0.5, 0.6, false);
  double hx = 0.0, hy = 0.0, hz = 0.0, ftx, fty, ftz;
  const double delta = 1e-5, vn = -0.02, gn = 1e-4;
  const double fn =
      spring_dashpot(cm, 2e-5, 0.0, 0.0, 1.0, delta, 0.0, 0.0, vn, gn, hx, hy, hz, ftx, fty, ftz);
  EXPECT_DOUBLE_EQ(fn, 3.5 * delta - gn * vn);
  EXPECT_EQ(ftx, 0.0);
  EXPECT_EQ(fty, 0.0);
  EXPECT_EQ(ftz, 0.0);
}

// An approach faster than k delta / gamma pulls: the unclipped model returns the attractive
// force (restitution exactly e), the clipped one zero.
TEST(ContactKernels, ClippingForbidsAttractiveNormalForce) {
  double h[3] = {0, 0, 0}, ft[3];
  const double delta = 1e-7, vn = 0.1, gn = 1e-3;  // separating fast: k delta - g vn < 0
  const LinearSpringDashpot free_cm(3.5, 0.1, 0.5, 0.6, false), clip_cm(3.5, 0.1, 0.5, 0.6, true);
  EXPECT_LT(
      spring_dashpot(free_cm, 2e-5, 1, 0, 0, delta, vn, 0, 0, gn, h[0], h[1], h[2], ft[0], ft[1], ft[2]),
      0.0);
  EXPECT_EQ(
      spring_dashpot(clip_cm, 2e-5, 1, 0, 0, delta, vn, 0, 0, gn, h[0], h[1], h[2], ft[0], ft[1], ft[2]),
      0.0);
}

// Below the Coulomb limit the tangential spring grows by v_t dt and the force is
// -k_t h - gamma_t v_t; beyond it the force is capped at mu |F_n| and the spring is reset to
// what the capped force implies.
TEST(ContactKernels, TangentialSpringStickThenSlideAtCoulombLimit) {
  const double kn = 3.5, mu = 0.6, dt = 2e-5, gn = 1e-4, ratio = 0.5;
  const LinearSpringDashpot cm(kn, 0.1, ratio, mu, false);
  const double delta = 1e-5;  // F_n = 3.5e-5 N (no normal velocity)
  double hx = 0.0, hy = 0.0, hz = 0.0, ftx, fty, ftz;
  const double vt = 1e-3;  // m/s along x
  double fn = spring_dashpot(cm, dt, 0, 0, 1, delta, vt, 0, 0, gn, hx, hy, hz, ftx, fty, ftz);
  EXPECT_DOUBLE_EQ(hx, vt * dt);
  EXPECT_DOUBLE_EQ(ftx, -kn * vt * dt - ratio * gn * vt);
  EXPECT_LT(std::abs(ftx), mu * fn);
  // Enough displacement to slide: |F_t| = mu F_n, and the spring holds what that force implies.
  hx = 1e-3;
  fn = spring_dashpot(cm, dt, 0, 0, 1, delta, vt, 0, 0, gn, hx, hy, hz, ftx, fty, ftz);
  EXPECT_NEAR(std::hypot(ftx, fty, ftz), mu * fn, 1e-18);
  EXPECT_NEAR(hx, -(ftx + ratio * gn * vt) / kn, 1e-18);
}

// The shear spring is turned into the current tangent plane keeping its length.
TEST(ContactKernels, ShearSpringRotatesIntoTheTangentPlaneKeepingItsLength) {
  const LinearSpringDashpot cm(3.5, 0.1, 0.5, 1e9, false);  // no sliding
  double hx = 1e-6, hy = 0.0, hz = 1e-6, ftx, fty, ftz;     // tilted out of the plane z = const
  spring_dashpot(cm, 2e-5, 0, 0, 1, 1e-5, 0, 0, 0, 0.0, hx, hy, hz, ftx, fty, ftz);
  EXPECT_NEAR(hz, 0.0, 1e-22);
  EXPECT_NEAR(std::hypot(hx, hy), std::hypot(1e-6, 1e-6), 1e-20);
}

// Below the cap, the rolling resistance stops the relative rolling within one step: the
// torques -R_i q and +R_j q change w_i - w_j by -(a_i + a_j) q dt, a = R / I, which cancels the
// tangential part of the relative spin when the friction moment is zero.
TEST(ContactKernels, RollingResistanceStopsRelativeRollingWithinOneStep) {
  const double m = 3.0e-7, r = 0.3e-3, I = 0.4 * m * r * r, dt = 2e-5, a = r / I;
  const double wrel = 0.5;  // rad/s about x, contact normal along z
  double rx, ry, rz;
  rolling_resistance(wrel, 0, 0, 0, 0, 1, 0, 0, 0, a, a, 1.0 / dt, 1.0, rx, ry, rz);
  EXPECT_NEAR(wrel - (a + a) * rx * dt, 0.0, 1e-12 * wrel);
  // A spin about the normal is not rolling.
  rolling_resistance(0, 0, wrel, 0, 0, 1, 0, 0, 0, a, a, 1.0 / dt, 1.0, rx, ry, rz);
  EXPECT_EQ(std::hypot(rx, ry, rz), 0.0);
}

// Beyond the cap the torque is Eq. 11's constant mu_r |F_n| along the rolling direction.
TEST(ContactKernels, RollingResistanceIsCappedAtMuRTimesNormalForce) {
  const double m = 3.0e-7, r = 0.3e-3, I = 0.4 * m * r * r, a = r / I;
  const double qmax = 0.1 * 3.5e-5;
  double rx, ry, rz;
  rolling_resistance(0, 30.0, 0, 0, 0, 1, 0, 0, 0, a, 0.0, 1.0 / 2e-5, qmax, rx, ry, rz);
  EXPECT_NEAR(std::hypot(rx, ry, rz), qmax, 1e-15 * qmax);
  EXPECT_GT(ry, 0.0);
}

// A wall is a sphere of infinite inertia at rest: the pair kernel with a_j -> 0 tends to the wall
// kernel (a_j = 0).
TEST(ContactKernels, WallRollingIsThePairLimitOfInfiniteInertia) {
  const double m = 3.0e-7, r = 0.3e-3, I = 0.4 * m * r * r, a = r / I, inv_dt = 5e4;
  double wx, wy, wz, px, py, pz;
  rolling_resistance(0.2, -0.1, 0.05, 0, 1, 0, 1e-8, 0, -2e-8, a, 0.0, inv_dt, 1.0, wx, wy, wz);
  rolling_resistance(0.2, -0.1, 0.05, 0, 1, 0, 1e-8, 0, -2e-8, a, 1e-9 * a, inv_dt, 1.0, px, py, pz);
  EXPECT_NEAR(px, wx, 1e-8 * std::abs(wx));
  EXPECT_NEAR(pz, wz, 1e-8 * std::abs(wz));
  EXPECT_NEAR(py, 0.0, 1e-20);
}

}  // namespace
}  // namespace boycott::particles
