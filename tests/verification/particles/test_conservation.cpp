// Conservation in an elastic, frictionless gas of spheres in a fully periodic box.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "dem_test_util.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

TEST(ElasticGas, ConservesEnergyAndMomentum) {
  // 300 spheres, e = 1, no friction, no gravity, solid fraction 0.2. dt = t_c/50 of a pair.
  const double L = 12 * kD;
  const double tc = LinearSpringDashpot::collision_time(0.5 * particle_mass(), kKn, 1.0);
  DemSystem dem(make_config(L, false, 1.0, 0.0, 0.0, tc / 50.0));
  dem.insert_random(300, kR, kRho, {0, 0, 0}, {L, L, L}, 7);
  auto& s = dem.particles();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 0.05);
  for (std::size_t i = 0; i < s.n_local; ++i) {
    s.vx[i] = N(rng);
    s.vy[i] = N(rng);
    s.vz[i] = N(rng);
  }
  dem.initialize();
  auto momentum = [&](int c) {
    const auto& v = c == 0 ? s.vx : c == 1 ? s.vy : s.vz;
    double p = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i) p += s.mass[i] * v[i];
    return p;
  };
  double scale = 0.0;  // sum m |v|, the size of round-off in the momentum sum
  for (std::size_t i = 0; i < s.n_local; ++i) scale += s.mass[i] * std::abs(s.vx[i]);
  const double p0[3] = {momentum(0), momentum(1), momentum(2)};
  const double e0 = dem.kinetic_energy_j() + dem.spring_energy_j();
  double max_drift = 0.0;
  for (int n = 1; n <= 100000; ++n) {
    dem.step();
    if (n % 1000 == 0)
      max_drift = std::max(max_drift, std::abs(dem.kinetic_energy_j() + dem.spring_energy_j() - e0) / e0);
  }
  std::printf("[ report ] elastic gas: max |dE|/E over 1e5 steps = %.3e, %lld rebuilds\n", max_drift,
              static_cast<long long>(dem.rebuilds()));
  // Velocity Verlet is symplectic: the energy error stays bounded, O((w dt)^2) ~ 4e-3 per contact
  // at tc/50, diluted over the gas; 1e-3 is the stated bound.
  EXPECT_LT(max_drift, 1e-3);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(momentum(c) - p0[c]), 1e-12 * scale) << "component " << c;
}
