#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <set>

#include "particles/dem_system.hpp"
#include "particles/neighbor_list.hpp"

using namespace boycott::particles;

namespace {
constexpr double kR = 0.3e-3, kRho = 2650.0;

DemConfig gas_config(double L, double dt) {
  DemConfig c;
  c.box.len = {L, 0.6 * L, 1.3 * L};
  c.box.periodic = {true, true, true};
  c.dt_s = dt;
  c.skin_m = 0.3e-3;
  c.contact = LinearSpringDashpot(3.5, 0.9, 0.5, 0.3, false);
  c.rolling_model = "none";
  return c;
}

std::set<std::pair<std::int64_t, std::int64_t>> brute_force_pairs(const ParticleStore& s,
                                                                  const BoxGeometry& g, double cut) {
  std::set<std::pair<std::int64_t, std::int64_t>> out;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      double d2 = 0.0;
      const double dd[3] = {s.x[i] - s.x[j], s.y[i] - s.y[j], s.z[i] - s.z[j]};
      for (int k = 0; k < 3; ++k) {
        double d = dd[k];
        if (g.periodic[k]) d -= g.len[k] * std::round(d / g.len[k]);
        d2 += d * d;
      }
      if (d2 < cut * cut) out.insert({std::min(s.id[i], s.id[j]), std::max(s.id[i], s.id[j])});
    }
  return out;
}

/// Every overlapping pair of the store is in the current list (which may be an old one).
void expect_every_contact_listed(const DemSystem& dem, int step) {
  const auto& s = dem.particles();
  const auto& nl = dem.neighbor_list();
  std::set<std::pair<std::int64_t, std::int64_t>> listed;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (auto p = nl.offsets[i]; p < nl.offsets[i + 1]; ++p)
      listed.insert({std::min(s.id[i], s.id[nl.neighbors[p]]), std::max(s.id[i], s.id[nl.neighbors[p]])});
  for (const auto& pr : brute_force_pairs(s, dem.config().box, 2 * kR))
    ASSERT_TRUE(listed.count(pr)) << "missing contact " << pr.first << "-" << pr.second << " at step "
                                  << step;
}
}  // namespace

TEST(NeighborList, MatchesBruteForceAcrossPeriodicBoundaries) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    DemSystem dem(gas_config(6e-3, 2e-5));
    const auto& b = dem.config().box;
    dem.insert_random(400, kR, kRho, {0, 0, 0}, {b.len[0], b.len[1], b.len[2]}, seed);
    NeighborList nl;
    const double cut = 2 * kR + 0.3e-3;
    nl.build(dem.particles(), b, cut);
    const auto& s = dem.particles();
    std::set<std::pair<std::int64_t, std::int64_t>> got;
    for (std::size_t i = 0; i < s.size(); ++i)
      for (auto p = nl.offsets[i]; p < nl.offsets[i + 1]; ++p) {
        const auto j = nl.neighbors[p];
        EXPECT_GT(j, i);
        got.insert({std::min(s.id[i], s.id[j]), std::max(s.id[i], s.id[j])});
      }
    EXPECT_EQ(got.size(), nl.pair_count()) << "a pair is listed twice";
    EXPECT_EQ(got, brute_force_pairs(s, b, cut));
  }
}

TEST(NeighborList, RowsStoredByCellWithGhostsAppendedGiveEveryPairOnce) {
  // As on a rank of a parallel run: the rows sorted cell by cell, then copies of other particles
  // appended as ghosts (partners only). Every pair with a row and a later index within the
  // cutoff is listed once, in the row of its lower index, whatever the cells of the ghosts.
  for (unsigned seed = 1; seed <= 3; ++seed) {
    DemSystem dem(gas_config(6e-3, 2e-5));
    const auto& b = dem.config().box;
    dem.insert_random(500, kR, kRho, {0, 0, 0}, {b.len[0], b.len[1], b.len[2]}, seed);
    ParticleStore s = dem.particles();
    const double cut = 2 * kR + 0.3e-3;
    NeighborList nl;
    const auto order = nl.bin_and_order(s, b, cut);
    s.permute(order);
    // 300 of the sorted particles stay rows, in their order; the others become ghosts, appended
    // in reverse order (out of cell order).
    ParticleStore rows_then_ghosts = s;
    const std::size_t rows = 300;
    std::vector<std::size_t> reorder, ghosts;
    for (std::size_t k = 0; k < s.size(); ++k)
      (k % 3 != 1 && reorder.size() < rows ? reorder : ghosts).push_back(k);
    reorder.insert(reorder.end(), ghosts.rbegin(), ghosts.rend());
    ASSERT_EQ(reorder.size(), s.size());
    rows_then_ghosts.permute(reorder);
    nl.build(rows_then_ghosts, b, cut, rows);
    const auto& t = rows_then_ghosts;
    std::set<std::pair<std::int64_t, std::int64_t>> got, want;
    for (std::size_t i = 0; i < t.size(); ++i)
      for (auto p = nl.offsets[i]; p < nl.offsets[i + 1]; ++p) {
        ASSERT_LT(i, rows);
        ASSERT_GT(nl.neighbors[p], i);
        got.insert({t.id[i], t.id[nl.neighbors[p]]});
      }
    EXPECT_EQ(got.size(), nl.pair_count()) << "a pair is listed twice";
    for (const auto& pr : brute_force_pairs(t, b, cut)) {
      std::size_t a = 0, c = 0;
      for (std::size_t k = 0; k < t.size(); ++k) {
        if (t.id[k] == pr.first) a = k;
        if (t.id[k] == pr.second) c = k;
      }
      if (std::min(a, c) < rows) want.insert({t.id[std::min(a, c)], t.id[std::max(a, c)]});
    }
    EXPECT_EQ(got, want);
  }
}

TEST(NeighborList, HoldsEveryContactAfterManyRebuilds) {
  // A moving gas: at every step every overlapping pair must be in the (possibly old) list.
  DemSystem dem(gas_config(6e-3, 2e-5));
  const auto& b = dem.config().box;
  dem.insert_random(500, kR, kRho, {0, 0, 0}, {b.len[0], b.len[1], b.len[2]}, 5);
  auto& s = dem.particles();
  std::mt19937_64 rng(1);
  std::normal_distribution<double> N(0.0, 0.3);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.vx[i] = N(rng) + 0.5;  // a mean drift across the periodic faces too
    s.vy[i] = N(rng);
    s.vz[i] = N(rng) - 0.7;
  }
  dem.initialize();
  for (int n = 0; n < 3000; ++n) {
    dem.step();
    if (n % 50 != 0) continue;
    expect_every_contact_listed(dem, n);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(dem.rebuilds(), 20);
}

TEST(NeighborList, RebuildsWhenTheDisplacementsSpreadByMoreThanTheSkin) {
  // Rows of spheres that never touch, a third of them gliding along x at V, the rest at rest:
  // the displacements span [0, V t], so about their bounding box's centre every particle is
  // within V t / 2, and the list must be rebuilt once V t exceeds the skin: every
  // floor(skin / (V dt)) + 1 = 22 steps. About the mean displacement (V t / 3) the farthest
  // particle is 2 V t / 3 away: that rule would rebuild every 17 steps.
  const double V = 0.7, dt = 2e-5, a = 4 * kR;
  DemSystem dem(gas_config(6e-3, dt));
  const auto& b = dem.config().box;
  std::int64_t id = 0;
  for (int iy = 0; iy < 3; ++iy)
    for (int ix = 0; ix * a < b.len[0] - a; ++ix)
      for (int iz = 0; iz * a < b.len[2] - a; ++iz)
        dem.add_particle(id++, (ix + 0.5) * a, (iy + 0.5) * a, (iz + 0.5) * a, kR, kRho);
  auto& s = dem.particles();
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.y[i] < a) s.vx[i] = V;  // the bottom row of three
  dem.initialize();
  const auto r0 = dem.rebuilds();
  const int steps = 22 * 50;
  for (int n = 0; n < steps; ++n) dem.step();
  EXPECT_EQ(dem.contact_count(), 0);
  EXPECT_EQ(dem.rebuilds() - r0, 50);
}

TEST(NeighborList, HoldsEveryContactInALayerSlidingOverABedAtRest) {
  // A dense packing whose lower half slides fast along x and z over the upper half at rest (no
  // gravity): the pairs across the shear plane come into contact between rebuilds.
  DemSystem dem(gas_config(6e-3, 2e-5));
  const auto& b = dem.config().box;
  dem.insert_random(450, kR, kRho, {0, 0, 0}, {b.len[0], b.len[1], b.len[2]}, 9);
  auto& s = dem.particles();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 0.05);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool sliding = s.y[i] < 0.5 * b.len[1];
    s.vx[i] = (sliding ? 0.8 : 0.0) + N(rng);
    s.vy[i] = N(rng);
    s.vz[i] = (sliding ? -0.5 : 0.0) + N(rng);
  }
  dem.initialize();
  std::int64_t most_contacts = 0;
  for (int n = 0; n < 2000; ++n) {
    dem.step();
    most_contacts = std::max(most_contacts, dem.contact_count());
    expect_every_contact_listed(dem, n);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(most_contacts, 20);
  EXPECT_GT(dem.rebuilds(), 20);
}

TEST(ContactHistory, SurvivesRebuildsAndPeriodicWrap) {
  // Two spheres pressed together and sheared across the periodic x face: forcing a list rebuild
  // (which re-sorts and wraps) at every step must not change the tangential force history.
  auto run = [](bool rebuild_every_step) {
    DemConfig c = gas_config(6e-3, 2e-5);
    DemSystem dem(c);
    dem.add_particle(0, 6e-3 - 0.2e-3, 1e-3, 1e-3, kR, kRho);  // straddles x = L
    dem.add_particle(1, 6e-3 - 0.2e-3, 1e-3 + 2 * kR - 1e-5, 1e-3, kR, kRho);
    auto& s = dem.particles();
    s.ext_y = {0.35e-4, -0.35e-4};  // N, presses the pair together
    s.vx = {0.005, -0.005};
    dem.initialize();
    for (int n = 0; n < 100; ++n) {
      dem.step();
      if (rebuild_every_step) dem.force_rebuild();
    }
    const int i0 = s.id[0] == 0 ? 0 : 1;
    return std::array<double, 3>{s.fx[i0], s.vx[i0], s.x[i0]};
  };
  const auto a = run(false), b = run(true);
  EXPECT_NE(a[0], 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-12 * (std::abs(a[k]) + 1e-30)) << k;
}

TEST(Insertion, NonOverlappingAndSeeded) {
  DemSystem a(gas_config(6e-3, 2e-5)), b(gas_config(6e-3, 2e-5));
  const auto& bx = a.config().box;
  a.insert_random(300, kR, kRho, {0, 0, 0}, {bx.len[0], bx.len[1], bx.len[2]}, 9);
  b.insert_random(300, kR, kRho, {0, 0, 0}, {bx.len[0], bx.len[1], bx.len[2]}, 9);
  EXPECT_EQ(a.particles().x, b.particles().x);
  EXPECT_TRUE(brute_force_pairs(a.particles(), bx, 2 * kR).empty());
  DemSystem c(gas_config(2e-3, 2e-5));
  EXPECT_THROW(c.insert_random(2000, kR, kRho, {0, 0, 0}, {2e-3, 1.2e-3, 2.6e-3}, 1), std::exception);
}

/// A channel between walls at y = 0 and 3.6 mm under inclined gravity, with rolling friction.
DemConfig channel_config() {
  DemConfig c = gas_config(6e-3, 2e-5);
  c.gravity_m_s2 = {0.0, -3.0, -8.0};
  c.box.periodic = {true, false, true};
  c.walls = {PlaneWall{0, 0, 0, 0, 1, 0}, PlaneWall{0, 3.6e-3, 0, 0, -1, 0}};
  c.rolling_model = "constant_directional";
  c.rolling_friction = 0.1;
  return c;
}

/// 300 spheres falling in that channel, initialised: dry, or wet (a drag coefficient of
/// 1e-5 kg/s on each and the drag impulse tracked, as in a coupled sub-cycle).
DemSystem settling_channel(bool dry) {
  DemConfig c = channel_config();
  c.dry = dry;
  c.track_drag_impulse = !dry;
  DemSystem d(c);
  d.insert_random(300, kR, kRho, {0, 0, 0}, {6e-3, 3.6e-3, 7.8e-3}, 4);
  for (std::size_t i = 0; i < d.particles().n_local; ++i) d.particles().beta[i] = 1e-5;
  d.initialize();
  return d;
}

TEST(DemState, ExportImportContinuesBitwise) {
  auto make = [] { return channel_config(); };
  DemSystem a(make());
  a.insert_random(300, kR, kRho, {0, 0, 0}, {6e-3, 3.6e-3, 7.8e-3}, 4);
  a.initialize();
  for (int n = 0; n < 2000; ++n) a.step();
  const DemState st = a.export_state();
  DemSystem b(make());
  b.import_state(st);
  for (int n = 0; n < 2000; ++n) {
    a.step();
    b.step();
  }
  EXPECT_EQ(a.particles().x, b.particles().x);
  EXPECT_EQ(a.particles().vz, b.particles().vz);
  EXPECT_EQ(a.particles().wx, b.particles().wx);
}

TEST(DemSystem, FusedSubCycleEqualsSeparateStepsBitwise) {
  // advance(k) fuses each step's closing half kick with the next one's opening kick and drift;
  // a coupled sub-cycle (implicit drag, fluid force, added mass, drag impulse tracked) must
  // end where k calls of step() end, bit for bit, including the impulse owed to the fluid.
  auto make = [] {
    DemConfig c = channel_config();
    c.track_drag_impulse = true;
    DemSystem d(c);
    d.insert_random(300, kR, kRho, {0, 0, 0}, {6e-3, 3.6e-3, 7.8e-3}, 4);
    return d;
  };
  DemSystem a = make(), b = make();
  for (DemSystem* d : {&a, &b}) {
    auto& s = d->particles();
    for (std::size_t i = 0; i < s.n_local; ++i) {
      s.beta[i] = 1e-5 * (1.0 + 0.01 * static_cast<double>(i % 7));
      s.ufz[i] = 0.01 * std::sin(static_cast<double>(i));
      s.ext_y[i] = 1e-9 * std::cos(static_cast<double>(i));
      s.madd[i] = 0.5 * s.mass[i] / 2.65;
    }
    d->initialize();
  }
  for (int cycle = 0; cycle < 40; ++cycle) {
    a.advance(50);
    for (int n = 0; n < 50; ++n) b.step();
  }
  const ParticleStore &sa = a.particles(), &sb = b.particles();
  EXPECT_GT(a.rebuilds(), 1);
  EXPECT_EQ(sa.x, sb.x);
  EXPECT_EQ(sa.y, sb.y);
  EXPECT_EQ(sa.vz, sb.vz);
  EXPECT_EQ(sa.wx, sb.wx);
  EXPECT_EQ(sa.drag_jz, sb.drag_jz);
  EXPECT_EQ(sa.drag_jy, sb.drag_jy);
  EXPECT_EQ(a.time_s(), b.time_s());
  EXPECT_EQ(a.steps(), b.steps());
}

TEST(DemSystem, FusedStepsReportEachStepsVzSumBitwise) {
  // The dem_only scene averages the mean v_z of every step but runs the steps through advance(k),
  // whose fused passes never store the end-of-step velocities: advance's per-step sums must be
  // those of summing particles().vz (in storage order) after each step(), dry (as that scene
  // runs) and wet (the drag impulse tracked), across chunks and list rebuilds.
  for (const bool dry : {true, false}) {
    DemSystem a = settling_channel(dry), b = settling_channel(dry);
    std::vector<double> fused, stepped;
    for (const int count : {1, 37, 200, 2, 500}) {
      std::vector<double> sums(static_cast<std::size_t>(count), -1.0);
      a.advance(count, sums.data());
      fused.insert(fused.end(), sums.begin(), sums.end());
      for (int n = 0; n < count; ++n) {
        b.step();
        double sum = 0.0;
        for (std::size_t i = 0; i < b.particles().n_local; ++i) sum += b.particles().vz[i];
        stepped.push_back(sum);
      }
    }
    EXPECT_GT(a.rebuilds(), 1) << "dry " << dry;
    ASSERT_EQ(fused.size(), stepped.size());
    for (std::size_t k = 0; k < fused.size(); ++k)
      ASSERT_EQ(fused[k], stepped[k]) << "step " << k << " dry " << dry;
    EXPECT_EQ(a.particles().vz, b.particles().vz);
    EXPECT_NE(stepped.front(), stepped.back());  // the particles fall: the sums move
  }
}

TEST(DemSystem, InterruptibleStepsAskTheStopOnScheduleAndMatchPlainStepsBitwise) {
  // A long coupled step asks for a stop every check_every sub-steps, the fused passes running on
  // across the asks: it must ask after steps 7, 14, ... but never after the last, end where as
  // many step() calls end (bit for bit) when no stop comes, and stop after the asked step when
  // one does, with that step closed (its velocities those of step() calls).
  auto expect_same = [](const DemSystem& a, const DemSystem& b, const char* what) {
    EXPECT_EQ(a.particles().x, b.particles().x) << what;
    EXPECT_EQ(a.particles().vz, b.particles().vz) << what;
    EXPECT_EQ(a.particles().wx, b.particles().wx) << what;
    EXPECT_EQ(a.particles().drag_jz, b.particles().drag_jz) << what;
    EXPECT_EQ(a.time_s(), b.time_s()) << what;
    EXPECT_EQ(a.steps(), b.steps()) << what;
  };
  DemSystem a = settling_channel(false), b = settling_channel(false);
  int asks = 0;
  const std::function<bool()> never = [&] {
    ++asks;
    return false;
  };
  for (int cycle = 0; cycle < 40; ++cycle) {
    asks = 0;
    EXPECT_EQ(a.advance_interruptible(50, 7, never), 50);
    for (int n = 0; n < 50; ++n) b.step();
    EXPECT_EQ(asks, 7);  // after steps 7, 14, ..., 49
  }
  EXPECT_GT(a.rebuilds(), 1);
  expect_same(a, b, "no stop");

  asks = 0;
  const std::function<bool()> third = [&] { return ++asks == 3; };
  EXPECT_EQ(a.advance_interruptible(50, 7, third), 21);
  for (int n = 0; n < 21; ++n) b.step();
  expect_same(a, b, "stopped at the third ask");
}

TEST(DemSystem, EqualRadiusPathEqualsTheGatheredOneBitwise) {
  // Equal radii are taken as constants by the contact search and loop (rolling friction on, so
  // R / I is too); a system told its sizes changed gathers them per pair. A bed forms on the
  // lower wall, so thousands of contacts are evaluated both ways.
  auto make = [] {
    DemSystem d(channel_config());
    d.insert_random(300, kR, kRho, {0, 0, 0}, {6e-3, 3.6e-3, 7.8e-3}, 4);
    d.initialize();
    return d;
  };
  DemSystem a = make(), b = make();
  b.particle_sizes_changed();
  EXPECT_TRUE(a.equal_radii());
  EXPECT_FALSE(b.equal_radii());
  std::int64_t contacts = 0;
  for (int n = 0; n < 3000; ++n) {
    a.step();
    b.step();
    contacts += a.contact_count();
  }
  EXPECT_GT(contacts, 10000);
  EXPECT_FALSE(b.equal_radii());  // nothing but initialize() or import_state() turns it back on
  EXPECT_EQ(a.particles().x, b.particles().x);
  EXPECT_EQ(a.particles().y, b.particles().y);
  EXPECT_EQ(a.particles().vz, b.particles().vz);
  EXPECT_EQ(a.particles().wx, b.particles().wx);
  EXPECT_EQ(a.particles().tz, b.particles().tz);
}

TEST(DemSystem, AParticleOfAnotherSizeEndsTheEqualRadiusPath) {
  DemSystem d(channel_config());
  d.insert_random(50, kR, kRho, {0, 0, 0}, {6e-3, 3.6e-3, 7.8e-3}, 4);
  d.initialize();
  EXPECT_TRUE(d.equal_radii());
  d.add_particle(1000, 3e-3, 1.8e-3, 7.0e-3, 0.5 * kR, kRho);
  EXPECT_FALSE(d.equal_radii());
  d.initialize();
  EXPECT_FALSE(d.equal_radii());
}
