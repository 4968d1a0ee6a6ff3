// Velocity Verlet on a single permanent contact (a harmonic oscillator): convergence order 2,
// and the implicit drag hook on a stiff particle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dem_test_util.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

namespace {
/// A sphere pressed onto the wall y = 0 by a constant force F, released from the unloaded
/// position with zero velocity: undamped (e = 1), it oscillates about delta_eq = F/k with
/// amplitude delta_eq, y(t) = R - delta_eq (1 - cos(w t)), w = sqrt(k/m); the contact never
/// opens. Returns |y(T) - exact|.
double oscillator_error(double dt, double T) {
  DemSystem dem(make_config(20 * kD, true, 1.0, 0.0, 0.0, dt));
  dem.add_particle(0, 5 * kD, kR, 5 * kD, kR, kRho);
  auto& s = dem.particles();
  const double F = 2e-4;
  s.ext_y[0] = -F;
  dem.initialize();
  const auto n = std::llround(T / dt);
  for (long long k = 0; k < n; ++k) dem.step();
  const double w = std::sqrt(kKn / s.mass[0]);
  const double exact = kR - F / kKn * (1.0 - std::cos(w * dem.time_s()));
  return std::abs(s.y[0] - exact);
}
}  // namespace

TEST(VelocityVerlet, ConvergesAtSecondOrderOnHarmonicContact) {
  const double w = std::sqrt(kKn / particle_mass());
  const double period = 2 * kPi / w;
  const double T = 3.3 * period;
  const double e1 = oscillator_error(period / 40, T), e2 = oscillator_error(period / 80, T),
               e3 = oscillator_error(period / 160, T);
  const double o1 = std::log2(e1 / e2), o2 = std::log2(e2 / e3);
  std::printf("[ report ] oscillator errors %.3e %.3e %.3e, observed orders %.3f %.3f\n", e1, e2, e3, o1, o2);
  EXPECT_NEAR(o1, 2.0, 0.1);
  EXPECT_NEAR(o2, 2.0, 0.1);
}

TEST(ImplicitDrag, StiffParticleRelaxesToTerminalVelocity) {
  // Response time m/beta = dt/1000: explicit drag would blow up; the implicit update relaxes
  // monotonically to v = m g / beta.
  const double dt = 20e-6;
  auto cfg = make_config(20 * kD, false, 0.1, 0.6, 0.1, dt);
  cfg.gravity_m_s2 = {0.0, 0.0, -9.81};
  DemSystem dem(cfg);
  dem.add_particle(0, 5 * kD, 5 * kD, 5 * kD, kR, kRho);
  auto& s = dem.particles();
  s.beta[0] = 1000.0 * s.mass[0] / dt;
  dem.initialize();
  const double vt = -s.mass[0] * 9.81 / s.beta[0];
  double prev = 0.0;
  for (int n = 0; n < 50; ++n) {
    dem.step();
    EXPECT_LE(s.vz[0], prev + 1e-18) << "not monotone at step " << n;
    EXPECT_GE(s.vz[0], vt * (1 + 1e-12)) << "overshoot at step " << n;
    prev = s.vz[0];
  }
  EXPECT_NEAR(s.vz[0], vt, 1e-9 * std::abs(vt));
}
