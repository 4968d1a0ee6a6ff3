// The DEM on several MPI ranks (particles/parallel_dem.cpp) against the same DEM on one:
// collisions across a slab face, wall contacts that cross a face, particles that all start on
// one rank, and a dilute gas, each compared particle by particle with the serial run computed
// on every rank. Run under mpirun with 2 and 3 ranks.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "dem_test_util.hpp"
#include "particles/min_image.hpp"

using namespace boycott;
using namespace boycott::particles;
using namespace boycott::particles::testing;

namespace {

struct State {
  double x, y, z, vx, vy, vz, wx, wy, wz;
};

int rank_count() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// Uniform z-slabs of the box [0, L) over all ranks.
SlabDecomposition uniform_slabs(double L) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return SlabDecomposition::gather(MPI_COMM_WORLD, L * rank / size, L * (rank + 1) / size);
}

/// Runs `steps` DEM steps of the particles `add` places, on all ranks (parallel) or on this one
/// (serial), in calls of advance(chunk) (fused kicks between the steps of a call), and returns
/// every particle's state by id (on every rank).
std::map<std::int64_t, State> run(const DemConfig& cfg, const std::function<void(DemSystem&)>& add, int steps,
                                  bool parallel, std::int64_t* migrations = nullptr, int chunk = 1) {
  DemSystem dem(cfg);
  add(dem);
  if (parallel) dem.decompose(uniform_slabs(cfg.box.len[2]));
  dem.initialize();
  for (int k = 0; k < steps; k += chunk) dem.advance(std::min(chunk, steps - k));
  const auto& s = dem.particles();
  std::vector<double> mine;
  for (std::size_t i = 0; i < s.n_local; ++i)
    mine.insert(mine.end(), {static_cast<double>(s.id[i]), s.x[i], s.y[i], s.z[i], s.vx[i], s.vy[i], s.vz[i],
                             s.wx[i], s.wy[i], s.wz[i]});
  std::vector<double> all = mine;
  if (parallel) {
    const int n = static_cast<int>(mine.size());
    const int size = rank_count();
    std::vector<int> counts(size), displs(size);
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
    all.resize(static_cast<std::size_t>(total));
    MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                   MPI_COMM_WORLD);
    if (migrations) *migrations = global_sum(MPI_COMM_WORLD, dem.migrations());
  }
  std::map<std::int64_t, State> out;
  for (std::size_t k = 0; k + 10 <= all.size(); k += 10)
    out[static_cast<std::int64_t>(all[k])] = State{all[k + 1], all[k + 2], all[k + 3], all[k + 4], all[k + 5],
                                                   all[k + 6], all[k + 7], all[k + 8], all[k + 9]};
  return out;
}

/// Largest difference in position (m) between two runs, through the periodic images of a box
/// of side L (the runs wrap coordinates at their own rebuilds); fails when a particle is missing.
double max_position_difference(const std::map<std::int64_t, State>& a, const std::map<std::int64_t, State>& b,
                               double L) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  const auto d = [L](double u, double v) { return std::abs(min_image(u - v, L, 1.0 / L)); };
  for (const auto& [id, s] : a) {
    const auto it = b.find(id);
    if (it == b.end()) {
      ADD_FAILURE() << "particle " << id << " is missing";
      continue;
    }
    worst = std::max({worst, d(s.x, it->second.x), d(s.y, it->second.y), d(s.z, it->second.z)});
  }
  return worst;
}

// A head-on collision whose contact point is the face between two ranks' slabs (z = L/2 on 2
// ranks, L/3 on 3): the rebound has the analytic restitution, as on one rank.
TEST(ParallelDem, PairCollisionAcrossACutReboundsWithTheAnalyticRestitution) {
  const double L = 20 * kD, e = 0.1, v0 = 0.05, cut = L / rank_count();
  const auto cfg = make_config(L, false, e, 0.0, 0.0, 2e-6);
  auto add = [&](DemSystem& dem) {
    dem.add_particle(0, 0.5 * L, 0.5 * L, cut - kR - 2e-6, kR, kRho);
    dem.add_particle(1, 0.5 * L, 0.5 * L, cut + kR + 2e-6, kR, kRho);
    dem.particles().vz[0] = v0;
    dem.particles().vz[1] = -v0;
  };
  const int steps = 2000;  // the contact lasts ~700 steps of 2 us
  const auto par = run(cfg, add, steps, true), ser = run(cfg, add, steps, false);
  const double rest = (par.at(1).vz - par.at(0).vz) / (2 * v0);
  std::printf("[ report ] restitution across the cut %.6f (serial %.6f, e = %.2f)\n", rest,
              (ser.at(1).vz - ser.at(0).vz) / (2 * v0), e);
  EXPECT_NEAR(rest, e, 0.01 * e);
  EXPECT_LT(max_position_difference(par, ser, L), 1e-15);
}

// A particle sliding down the wall y = 0 along z crosses the face between two slabs with its
// wall contact (tangential spring) intact: the same trajectory as on one rank.
TEST(ParallelDem, ParticleSlidingOnAWallAcrossACutKeepsItsWallHistory) {
  const double L = 20 * kD, cut = L / rank_count();
  auto cfg = make_config(L, true, 0.1, 0.6, 0.1, 2e-5);
  cfg.gravity_m_s2 = {0.0, -9.81 * std::cos(0.5), -9.81 * std::sin(0.5)};
  auto add = [&](DemSystem& dem) {
    dem.add_particle(0, 0.5 * L, kR - 1e-6, cut + 4 * kR, kR, kRho);
    dem.add_particle(1, 0.2 * L, kR - 1e-6, cut + 6 * kR, kR, kRho);
  };
  std::int64_t migrations = 0;
  const auto par = run(cfg, add, 3000, true, &migrations), ser = run(cfg, add, 3000, false);
  std::printf("[ report ] wall-sliding particles: %lld migrations, z %.6f -> %.6f m (serial %.6f)\n",
              static_cast<long long>(migrations), cut + 4 * kR, par.at(0).z, ser.at(0).z);
  EXPECT_GE(migrations, 2);  // both crossed the face (or the periodic end) at least once
  EXPECT_LT(max_position_difference(par, ser, L), 1e-15);
}

/// n particles at random, non-overlapping, in z < z_max.
void add_random(DemSystem& dem, int n, double z_max, std::uint64_t seed) {
  const auto& b = dem.config().box;
  dem.insert_random(n, kR, kRho, b.lo, {b.lo[0] + b.len[0], b.lo[1] + b.len[1], z_max}, seed, 0.1 * kR);
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> v(0.0, 0.02);
  auto& s = dem.particles();
  for (std::size_t i = 0; i < s.size(); ++i) s.vx[i] = v(rng), s.vy[i] = v(rng), s.vz[i] = v(rng);
}

// All particles start on rank 0's slab and spread under gravity along -z (periodic) over the
// other ranks: the same as on one rank, to round-off growth over 4000 steps.
TEST(ParallelDem, ParticlesAllStartingOnOneRankRunAsOnOne) {
  const double L = 16 * kD;
  auto cfg = make_config(L, true, 0.3, 0.5, 0.1, 2e-5);
  cfg.gravity_m_s2 = {0.0, -2.0, -9.0};
  auto add = [&](DemSystem& dem) { add_random(dem, 150, L / rank_count(), 11); };
  std::int64_t migrations = 0;
  const auto par = run(cfg, add, 4000, true, &migrations), ser = run(cfg, add, 4000, false);
  const double diff = max_position_difference(par, ser, L);
  std::printf("[ report ] 150 particles from one slab: %lld migrations, largest position difference %.3g m\n",
              static_cast<long long>(migrations), diff);
  EXPECT_GE(migrations, 100);
  EXPECT_LT(diff, 1e-9);
}

// A dilute gas in a periodic box: every particle count and position as on one rank.
TEST(ParallelDem, DiluteGasMatchesOneRank) {
  const double L = 16 * kD;
  const auto cfg = make_config(L, false, 0.5, 0.3, 0.0, 2e-5);
  auto add = [&](DemSystem& dem) { add_random(dem, 200, L, 5); };
  std::int64_t migrations = 0;
  const auto par = run(cfg, add, 3000, true, &migrations), ser = run(cfg, add, 3000, false);
  const double diff = max_position_difference(par, ser, L);
  std::printf("[ report ] dilute gas: %lld migrations, largest position difference %.3g m\n",
              static_cast<long long>(migrations), diff);
  EXPECT_LT(diff, 1e-10);
}

// A dense layer sliding along z over particles at rest, across the slab faces, with no limit on
// how far a particle may leave its slab between rebuilds: the list's bound alone must keep
// every pair across a face (a ghost was within the cutoff of the slab at the build), so the
// run is the one-rank run.
TEST(ParallelDem, ALayerSlidingAcrossTheCutsBetweenRebuildsRunsAsOnOne) {
  const double L = 16 * kD;
  auto cfg = make_config(L, true, 0.5, 0.5, 0.1, 2e-5);
  cfg.slab_excursion_m = std::numeric_limits<double>::infinity();
  auto add = [&](DemSystem& dem) {
    add_random(dem, 700, L, 21);
    auto& s = dem.particles();
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.y[i] < 0.5 * L) s.vz[i] += 0.6;
  };
  std::int64_t migrations = 0;
  const auto par = run(cfg, add, 2000, true, &migrations), ser = run(cfg, add, 2000, false);
  const double diff = max_position_difference(par, ser, L);
  std::printf("[ report ] sliding layer: %lld migrations, largest position difference %.3g m\n",
              static_cast<long long>(migrations), diff);
  EXPECT_GE(migrations, 50);
  EXPECT_LT(diff, 1e-10);
}

// The sliding layer again with the contact search's near pairs on several ranks (each rank
// renews its own from its particles and ghost copies; calls of advance(10), whose steps drift in
// fused kick passes) against one rank testing the whole list.
TEST(ParallelDem, NearPairsOnSeveralRanksRunAsTheWholeListOnOne) {
  const double L = 16 * kD;
  auto cfg = make_config(L, true, 0.5, 0.5, 0.1, 2e-5);
  auto whole = cfg;
  whole.near_pairs = false;
  auto add = [&](DemSystem& dem) {
    add_random(dem, 700, L, 23);
    auto& s = dem.particles();
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.y[i] < 0.5 * L) s.vz[i] += 0.6;
  };
  const auto par = run(cfg, add, 2000, true, nullptr, 10), ser = run(whole, add, 2000, false, nullptr, 10);
  const auto par_whole = run(whole, add, 2000, true, nullptr, 10);
  const double diff = max_position_difference(par, ser, L);
  std::printf(
      "[ report ] sliding layer, near pairs on %d ranks against the whole list on one: largest position "
      "difference %.3g m\n",
      rank_count(), diff);
  EXPECT_LT(diff, 1e-10);
  // on the same ranks, the same bits
  EXPECT_EQ(max_position_difference(par, par_whole, L), 0.0);
}

// Two layers of spheres facing each other across the first slab face, 0.12 mm apart (beyond
// the 0.1 mm margin), the upper one closing at 0.5 m/s: they touch after 12 steps, before the
// list's rebuild at 15. Each rank's own particles move as one (the box of their displacements
// has no extent), so only the ghost copies' displacements can renew its near pairs in time.
TEST(ParallelDem, NearPairsFollowGhostsClosingOnARankAtRest) {
  const double L = 16 * kD, gap = 0.12e-3, cut = L / rank_count();
  auto cfg = make_config(L, true, 0.5, 0.5, 0.1, 2e-5);
  auto whole = cfg;
  whole.near_pairs = false;
  auto add = [&](DemSystem& dem) {
    std::int64_t id = 0;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const double x = (a + 0.5) * L / 8, y = (b + 0.5) * L / 8;
        dem.add_particle(id++, x, y, cut - kR - 0.5 * gap, kR, kRho);
        dem.add_particle(id++, x, y, cut + kR + 0.5 * gap, kR, kRho);
      }
    auto& s = dem.particles();
    for (std::size_t i = 0; i < s.size(); ++i) s.vz[i] = s.z[i] > cut ? -0.5 : 0.0;
  };
  // one call of advance(40), as the coupled sub-cycle makes them
  const auto par = run(cfg, add, 40, true, nullptr, 40), par_whole = run(whole, add, 40, true, nullptr, 40);
  const auto ser = run(whole, add, 40, false, nullptr, 40);
  EXPECT_LT(max_position_difference(par, ser, L), 1e-10);
  EXPECT_EQ(max_position_difference(par, par_whole, L), 0.0);
  // the layers met: the resting one was pushed down
  double lowest = L;
  for (const auto& [id, st] : par)
    if (id % 2 == 0) lowest = std::min(lowest, st.z);
  EXPECT_LT(lowest, cut - kR - 0.5 * gap);
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  // One rank prints (every rank runs every test: they are collective).
  auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
  if (rank != 0) delete listeners.Release(listeners.default_result_printer());
  const int rc = RUN_ALL_TESTS();
  MPI_Finalize();
  return rc;
}
