// A bed of several layers settled on the lower wall with gravity inclined at 5 deg
// (tan 5 deg = 0.087 < mu_r = 0.1), Table III contact parameters: it must come to rest.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "dem_test_util.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

TEST(SettledBed, ComesToRestAtFiveDegrees) {
  const double th = 5.0 * kPi / 180.0;
  auto cfg = make_config(12 * kD, true, 0.1, 0.6, 0.1, 20e-6);
  cfg.box.len = {12 * kD, 10 * kD, 12 * kD};
  cfg.walls[1].py = 10 * kD;
  cfg.gravity_m_s2 = {0.0, -9.81 * std::cos(th), -9.81 * std::sin(th)};
  DemSystem dem(cfg);
  // About four layers: 4 x (12 x 12) spheres' worth, inserted loosely and dropped.
  dem.insert_random(480, kR, kRho, {0, 0, 0}, {12 * kD, 10 * kD, 12 * kD}, 11);
  dem.initialize();
  for (int n = 0; n < 50000; ++n) dem.step();  // 1 s
  const auto& s = dem.particles();
  const double N = static_cast<double>(s.n_local);
  const double ke_per_particle = dem.kinetic_energy_j() / N;
  // Reference: the potential energy of dropping one diameter, m g d.
  const double ref = particle_mass() * 9.81 * kD;
  double mean_vz = 0.0, ymax = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    mean_vz += s.vz[i] / N;
    ymax = std::max(ymax, s.y[i]);
  }
  std::printf("[ report ] settled bed: KE/particle = %.3e m g d, mean w_p = %.3e m/s, top at %.1f d\n",
              ke_per_particle / ref, mean_vz, ymax / kD);
  EXPECT_LT(ke_per_particle, 1e-6 * ref);
  EXPECT_LT(std::abs(mean_vz), 1e-5);
}
