// The contact search's near pairs (particles/contact_search.cpp): testing only the list pairs
// that were within a margin (skin / 3) of touching, renewed when a particle may have moved half
// of it, must find every contact the whole list finds, in the same order, so a run is the same
// bits with the near pairs on and off. Each case is built to need the renewals: a layer sliding
// over a bed between walls, two spheres closing from beyond the margin faster than it lasts, and
// spheres that grow into contact without moving.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "dem_test_util.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

namespace {

struct Outcome {
  std::vector<double> state;           ///< every particle's position, velocity and spin, in id order
  std::vector<std::int64_t> contacts;  ///< contact count after each call of advance
  std::int64_t rebuilds = 0, renewals = 0;
};

/// Runs `calls` x `chunk` steps of the particles `add` places with the near pairs on or off, in
/// calls of advance(chunk) (with chunk > 1 the steps of a call drift in fused kick passes, as
/// the coupled sub-cycle runs them), `between` before each call.
Outcome run(DemConfig cfg, bool near, const std::function<void(DemSystem&)>& add, int calls, int chunk,
            const std::function<void(DemSystem&, int)>& between = {}) {
  cfg.near_pairs = near;
  DemSystem dem(cfg);
  add(dem);
  dem.initialize();
  Outcome o;
  for (int k = 0; k < calls; ++k) {
    if (between) between(dem, k);
    dem.advance(chunk);
    o.contacts.push_back(dem.contact_count());
  }
  const auto& s = dem.particles();
  std::vector<std::size_t> by_id(s.n_local);
  for (std::size_t i = 0; i < s.n_local; ++i) by_id[static_cast<std::size_t>(s.id[i])] = i;
  for (std::size_t i : by_id)
    o.state.insert(o.state.end(),
                   {s.x[i], s.y[i], s.z[i], s.vx[i], s.vy[i], s.vz[i], s.wx[i], s.wy[i], s.wz[i]});
  o.rebuilds = dem.rebuilds();
  o.renewals = dem.near_pair_renewals();
  return o;
}

/// The same bits, value by value (EXPECT_EQ on doubles: no tolerance).
void expect_same_bits(const Outcome& near, const Outcome& whole) {
  ASSERT_EQ(near.state.size(), whole.state.size());
  std::size_t differ = 0;
  for (std::size_t k = 0; k < near.state.size(); ++k) differ += near.state[k] != whole.state[k];
  EXPECT_EQ(differ, 0u) << "of " << near.state.size() << " values";
  EXPECT_EQ(near.contacts, whole.contacts);
  EXPECT_EQ(whole.renewals, 0);
}

}  // namespace

// 700 spheres between two walls under gravity, the upper half thrown along z at 0.6 m/s over the
// lower: a sheared, packed layer where pairs close and open every few steps (200 calls of 10
// fused steps; the contact counts compared after each call).
TEST(NearPairs, ALayerShearedOverABedBetweenWallsRunsBitForBitAsTheWholeList) {
  const double L = 16 * kD;
  auto cfg = make_config(L, true, 0.5, 0.5, 0.1, 2e-5);
  cfg.gravity_m_s2 = {0.0, -9.0, -2.0};
  auto add = [&](DemSystem& dem) {
    dem.insert_random(700, kR, kRho, {0.0, 0.0, 0.0}, {L, L, L}, 21, 0.1 * kR);
    auto& s = dem.particles();
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.y[i] > 0.5 * L) s.vz[i] += 0.6;
  };
  const Outcome near = run(cfg, true, add, 200, 10), whole = run(cfg, false, add, 200, 10);
  std::printf(
      "[ report ] sheared layer: %lld list rebuilds, %lld near-pair renewals, %lld contacts at the end\n",
      static_cast<long long>(near.rebuilds), static_cast<long long>(near.renewals),
      static_cast<long long>(near.contacts.back()));
  expect_same_bits(near, whole);
  EXPECT_GT(near.contacts.back(), 200);
  // renewed between rebuilds too, not only at them
  EXPECT_GT(near.renewals, near.rebuilds);
}

// Two spheres closing at 1 m/s from a gap of 1.5 margins (20 um a step): the pair is left out of
// the first near pairs and must come in at a renewal before they touch, collide as with the
// whole list, and rebound.
TEST(NearPairs, SpheresClosingFromBeyondTheMarginCollideAsWithTheWholeList) {
  const double L = 16 * kD;
  const auto cfg = make_config(L, false, 0.5, 0.3, 0.0, 2e-5);
  const double margin = cfg.skin_m / 3.0;
  auto add = [&](DemSystem& dem) {
    const double gap = 1.5 * margin;
    dem.add_particle(0, 0.5 * L, 0.5 * L, 0.5 * L - kR - 0.5 * gap, kR, kRho);
    dem.add_particle(1, 0.5 * L, 0.5 * L, 0.5 * L + kR + 0.5 * gap, kR, kRho);
    auto& s = dem.particles();
    s.vz[0] = 0.5, s.vz[1] = -0.5;
  };
  const Outcome near = run(cfg, true, add, 400, 1), whole = run(cfg, false, add, 400, 1);
  expect_same_bits(near, whole);
  std::int64_t touching_steps = 0;
  for (auto c : near.contacts) touching_steps += c > 0;
  EXPECT_GT(touching_steps, 0);
  // vz of particle 0 (id order: x y z vx vy vz ...) after the rebound
  EXPECT_LT(near.state[5], 0.0);
}

// Spheres at rest 0.12 mm apart (more than the 0.1 mm margin) grow by 0.07 mm each, as a packing
// run grows them (particle_sizes_changed, no rebuild): they touch without moving, so the near
// pairs must be renewed for the new radii.
TEST(NearPairs, SpheresGrowingIntoContactWithoutMovingAreFound) {
  const double L = 16 * kD;
  const auto cfg = make_config(L, false, 0.5, 0.3, 0.0, 2e-5);
  const double gap = 0.12e-3, grow = 0.07e-3;
  auto add = [&](DemSystem& dem) {
    int id = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        dem.add_particle(id++, (a + 0.5) * (2 * kR + gap), 0.5 * L, (b + 0.5) * (2 * kR + gap), kR, kRho);
  };
  auto between = [&](DemSystem& dem, int k) {
    if (k != 10) return;
    auto& s = dem.particles();
    const double r = kR + grow, m = kRho * 4.0 / 3.0 * kPi * r * r * r;
    for (std::size_t i = 0; i < s.size(); ++i) s.radius[i] = r, s.mass[i] = m, s.inertia[i] = 0.4 * m * r * r;
    dem.particle_sizes_changed();
  };
  const Outcome near = run(cfg, true, add, 40, 1, between), whole = run(cfg, false, add, 40, 1, between);
  expect_same_bits(near, whole);
  EXPECT_EQ(near.contacts[5], 0);
  EXPECT_GT(near.contacts[12], 0);
  EXPECT_EQ(near.rebuilds, whole.rebuilds);
}
