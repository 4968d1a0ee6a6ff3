// Coupled CFD-DEM on several MPI ranks against the same case on one rank, computed in the same
// process on MPI_COMM_SELF: a dilute suspension solved tightly (the decomposition only changes
// the order of additions), a dense one whose particles change rank hundreds of times (compared
// with the spread that a one-ulp change of the initial positions causes on one rank), and the
// momentum budget of a periodic suspension. Run under mpirun with 2 and 3 ranks.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "core/case_params.hpp"
#include "core/constants.hpp"
#include "coupling/coupled_system.hpp"
#include "fluid/petsc_session.hpp"
#include "scenes/particle_setup.hpp"

namespace boycott {
namespace {

using Positions = std::map<std::int64_t, std::array<double, 3>>;

CaseParams make_case(const std::string& toml) {
  CaseParams p = parse_case_string(toml);
  validate(p);
  return p;
}

int world_size() {
  int n = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &n);
  return n;
}

/// Every particle's position, on every rank of comm.
Positions positions(coupling::CoupledSystem& run, MPI_Comm comm) {
  const auto& s = run.dem().particles();
  std::vector<double> mine;
  for (std::size_t i = 0; i < s.n_local; ++i)
    mine.insert(mine.end(), {static_cast<double>(s.id[i]), s.x[i], s.y[i], s.z[i]});
  int size = 1;
  MPI_Comm_size(comm, &size);
  const int n = static_cast<int>(mine.size());
  std::vector<int> counts(size), displs(size);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
  std::vector<double> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  Positions out;
  for (std::size_t k = 0; k + 4 <= all.size(); k += 4)
    out[static_cast<std::int64_t>(all[k])] = {all[k + 1], all[k + 2], all[k + 3]};
  return out;
}

/// Largest position difference (m) through the periodic images of x and z.
double max_difference(const Positions& a, const Positions& b, double Lx, double Lz) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  auto img = [](double d, double L) { return std::abs(d - L * std::nearbyint(d / L)); };
  for (const auto& [id, p] : a) {
    const auto it = b.find(id);
    if (it == b.end()) {
      ADD_FAILURE() << "particle " << id << " missing";
      continue;
    }
    worst = std::max({worst, img(p[0] - it->second[0], Lx), std::abs(p[1] - it->second[1]),
                      img(p[2] - it->second[2], Lz)});
  }
  return worst;
}

struct RunResult {
  Positions x;
  std::vector<double> alpha_first;  ///< alpha_f after the first deposit, whole grid
  std::int64_t particles = 0, migrations = 0;
  double volume_m3 = 0.0;
};

/// Places the case's particles, shares them over comm, runs `steps` CFD steps.
RunResult run_case(const CaseParams& p, MPI_Comm comm, int steps, bool perturb = false) {
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true}, comm);
  scenes::insert_case_particles(run.dem(), p);
  if (perturb) {
    auto& s = run.dem().particles();
    for (std::size_t i = 0; i < s.size(); ++i) s.z[i] = std::nextafter(s.z[i], 1.0);
  }
  run.start();
  RunResult r;
  r.alpha_first = run.fluid().gather(5);
  for (int k = 0; k < steps; ++k) run.step();
  r.x = positions(run, comm);
  r.particles = run.dem().global_count();
  r.volume_m3 = run.particle_volume_m3();
  std::int64_t m = run.dem().migrations();
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_INT64_T, MPI_SUM, comm);
  r.migrations = m;
  return r;
}

// A dilute suspension (solid fraction 0.02) with fixed SIMPLE iterations and linear systems
// solved to 1e-12: on 2 and 3 ranks the particles end where they end on one, to 1e-10 m after
// 20 CFD steps, and the first deposit gives alpha_f to 1e-12.
TEST(ParallelCoupling, DiluteSuspensionMatchesOneRank) {
  PetscOptionsSetValue(nullptr, "-pressure_ksp_rtol", "1e-12");
  PetscOptionsSetValue(nullptr, "-momentum_ksp_rtol", "1e-12");
  const CaseParams p = make_case(R"(
scene = "inclined_settling"
[domain]
length_x = 0.008
width_y = 0.006
height_z = 0.012
cells = [8, 6, 12]
[particles]
volume_fraction = 0.02
[gravity]
angle_deg = 65.0
[numerics]
simple_tolerance = 1e-30
simple_max_iterations = 6
)");
  const RunResult one = run_case(p, PETSC_COMM_SELF, 20), many = run_case(p, PETSC_COMM_WORLD, 20);
  PetscOptionsClearValue(nullptr, "-pressure_ksp_rtol");
  PetscOptionsClearValue(nullptr, "-momentum_ksp_rtol");
  double da = 0.0;
  for (std::size_t c = 0; c < one.alpha_first.size(); ++c)
    da = std::max(da, std::abs(one.alpha_first[c] - many.alpha_first[c]));
  const double dx = max_difference(one.x, many.x, 0.008, 0.012);
  std::printf(
      "[ report ] dilute, %d ranks: %lld particles, %lld migrations; alpha_f differs by %.2e, positions by "
      "%.2e m after 20 CFD steps\n",
      world_size(), static_cast<long long>(many.particles), static_cast<long long>(many.migrations), da, dx);
  EXPECT_LT(da, 1e-12);
  EXPECT_LT(dx, 1e-10);
  EXPECT_EQ(one.particles, many.particles);
}

// The same dilute suspension read with numerics.sampling = "trilinear" (each field from its own
// staggered nodes with the wall rules; the rank's z-window holds them like the kernel's): the
// ranks agree with one rank to the same bounds.
TEST(ParallelCoupling, TrilinearSamplingMatchesOneRank) {
  PetscOptionsSetValue(nullptr, "-pressure_ksp_rtol", "1e-12");
  PetscOptionsSetValue(nullptr, "-momentum_ksp_rtol", "1e-12");
  const CaseParams p = make_case(R"(
scene = "inclined_settling"
[domain]
length_x = 0.008
width_y = 0.006
height_z = 0.012
cells = [8, 6, 12]
[particles]
volume_fraction = 0.02
[gravity]
angle_deg = 65.0
[numerics]
simple_tolerance = 1e-30
simple_max_iterations = 6
sampling = "trilinear"
)");
  const RunResult one = run_case(p, PETSC_COMM_SELF, 20), many = run_case(p, PETSC_COMM_WORLD, 20);
  PetscOptionsClearValue(nullptr, "-pressure_ksp_rtol");
  PetscOptionsClearValue(nullptr, "-momentum_ksp_rtol");
  const double dx = max_difference(one.x, many.x, 0.008, 0.012);
  std::printf(
      "[ report ] dilute, trilinear sampling, %d ranks: %lld migrations; positions differ by %.2e m after 20 "
      "CFD steps\n",
      world_size(), static_cast<long long>(many.migrations), dx);
  EXPECT_LT(dx, 1e-10);
  EXPECT_EQ(one.particles, many.particles);
}

/// Table III's solid fraction at 60 deg in a box of nx x 6 x nz cells of 1 mm.
CaseParams dense_case(int nx, int nz) {
  return make_case(fmt::format(R"(
scene = "inclined_settling"
[domain]
length_x = {}
width_y = 0.006
height_z = {}
cells = [{}, 6, {}]
[particles]
volume_fraction = 0.113
[gravity]
angle_deg = 60.0
)",
                               nx / 1000.0, nz / 1000.0, nx, nz));
}

// A dense suspension (Table III's solid fraction 0.113) whose particles cross slab faces
// hundreds of times: the distance of the N-rank run from the one-rank run is within 10 times the
// distance a one-ulp change of every initial z makes on one rank (chaos amplifies both alike);
// particle count and volume are conserved.
TEST(ParallelCoupling, DenseSuspensionStaysWithinTheOneRankUlpSpread) {
  const CaseParams p = dense_case(12, 12);
  const int steps = 80;
  const RunResult one = run_case(p, PETSC_COMM_SELF, steps), ulp = run_case(p, PETSC_COMM_SELF, steps, true);
  const RunResult many = run_case(p, PETSC_COMM_WORLD, steps);
  const double d_ulp = max_difference(one.x, ulp.x, 0.012, 0.012),
               d_n = max_difference(one.x, many.x, 0.012, 0.012);
  std::printf(
      "[ report ] dense, %d ranks: %lld particles, %lld migrations in %d CFD steps; distance from one rank "
      "%.3e m, one-ulp spread on one rank %.3e m (ratio %.2f)\n",
      world_size(), static_cast<long long>(many.particles), static_cast<long long>(many.migrations), steps,
      d_n, d_ulp, d_n / d_ulp);
  EXPECT_GE(many.migrations, 100);
  EXPECT_LE(d_n, 10.0 * d_ulp);
  EXPECT_EQ(many.particles, one.particles);
  EXPECT_NEAR(many.volume_m3, one.volume_m3, 1e-12 * one.volume_m3);
}

// The rank report's "waiting" holds the time a rank waits for the one with more particle work.
// Every particle starts inside rank 0's slab (the others hold none), so in every DEM step the
// other ranks wait for rank 0 at the rebuild test's reduction, the first point where the ranks
// meet: their waiting is about rank 0's particle phases (contacts, lists, integration), and at
// least half of them. Before the reduction was timed, that wait showed in no phase (waiting read
// about 0 while the ranks' particle counts differed by 14 %). Checked where each rank has a core:
// with more ranks than cores the waits measure the scheduler as much as the imbalance.
TEST(ParallelCoupling, WaitingShowsTheParticleLoadImbalance) {
  const int ranks = world_size();
  const CaseParams p = dense_case(24, 48);
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true}, PETSC_COMM_WORLD);
  scenes::insert_case_particles(run.dem(), p);
  {
    // Rank 0's slab is the lowest 1/ranks of the z planes; 1 mm margins keep the particles in it
    // over the 40 steps (they settle by well under 1 mm).
    auto& s = run.dem().particles();
    const auto& b = run.dem().config().box;
    const double z0 = b.lo[2] + 1e-3, z1 = b.lo[2] + b.len[2] / ranks - 1e-3;
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.z[i] > z0 && s.z[i] < z1) keep.push_back(i);
    s.keep_increasing(keep);
  }
  run.start();
  for (int k = 0; k < 40; ++k) run.step();
  const nlohmann::json report = run.rank_report();
  const auto& per = report["per_rank"];
  ASSERT_EQ(static_cast<int>(per.size()), ranks);
  auto sec = [&](int r, const char* phase) { return per[r]["seconds"][phase].get<double>(); };
  const double work0 = sec(0, "dem_contacts") + sec(0, "neighbor_search") + sec(0, "integration");
  std::string waits;
  for (int r = 0; r < ranks; ++r) waits += (r ? ", " : "") + std::to_string(sec(r, "waiting"));
  std::printf("[ report ] %d ranks, particles per rank %s: rank 0 particle phases %.3f s, waiting %s s\n",
              ranks, report["particles"].dump().c_str(), work0, waits.c_str());
  EXPECT_GT(per[0]["particles"].get<std::int64_t>(), 0);
  if (ranks > static_cast<int>(std::thread::hardware_concurrency())) return;
  for (int r = 1; r < ranks; ++r) {
    EXPECT_LT(per[r]["particles"].get<std::int64_t>(), per[0]["particles"].get<std::int64_t>() / 10)
        << "rank " << r;
    EXPECT_GE(sec(r, "waiting"), 0.5 * work0) << "rank " << r;
  }
}

// The momentum budget of a fully periodic suspension closes on several ranks as on one: the
// change of fluid (BDF2) and particle momentum over the steps equals the external impulse
// (gravity, the driving gradient) minus the measured coupling lag.
TEST(ParallelCoupling, MomentumBudgetClosesOnSeveralRanks) {
  const CaseParams p = make_case(R"(
scene = "inclined_settling"
[fluid]
subgrid_model = "none"
[domain]
length_x = 0.008
width_y = 0.008
height_z = 0.008
cells = [8, 8, 8]
periodic_y = true
[particles]
count = 200
[gravity]
angle_deg = 90.0
[numerics]
simple_tolerance = 1e-10
simple_max_iterations = 200
)");
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true});
  const auto& b = run.dem().config().box;
  run.dem().insert_random(200, 0.3e-3, 2650.0, b.lo,
                          {b.lo[0] + b.len[0], b.lo[1] + b.len[1], b.lo[2] + b.len[2]}, 7);
  run.start();
  const double rho = 1000.0, V = 0.008 * 0.008 * 0.008, g = -9.81, vcell = V / 512.0;
  auto fluid_momentum = [&] {
    const auto w = run.fluid().gather(2), a = run.fluid().gather(5);
    double m = 0.0;
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const int c = i + 8 * (j + 8 * k), cm = i + 8 * (j + 8 * ((k + 7) % 8));
          m += rho * 0.5 * (a[c] + a[cm]) * w[c] * vcell;
        }
    return m;
  };
  auto particle_sum = [&](auto f) {
    const auto& s = run.dem().particles();
    double m = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i) m += f(s, i);
    return run.global_sum(m);
  };
  auto particle_momentum = [&] {
    return particle_sum([](const auto& s, std::size_t i) { return s.mass[i] * s.vz[i]; });
  };
  const double mp_total = particle_sum([](const auto& s, std::size_t i) { return s.mass[i]; });
  const double vs = run.particle_volume_m3();
  std::vector<double> M{fluid_momentum()}, P{particle_momentum()}, ext{0.0}, lag{0.0};
  const int N = 30;
  double dt = 0.0;
  for (int n = 1; n <= N; ++n) {
    dt = run.step().dt_s;
    M.push_back(fluid_momentum());
    P.push_back(particle_momentum());
    ext.push_back(dt * (mp_total * g + rho * g * (V - vs) - run.fluid().mean_pressure_gradient_pa_m() * V));
    lag.push_back(run.coupler().totals().lag_impulse_ns[2]);
  }
  run.coupler().prepare(run.dem(), run.fluid(), dt);
  lag.push_back(run.coupler().totals().lag_impulse_ns[2]);
  auto Q = [&](int n) { return 1.5 * M[n] - 0.5 * M[n - 1]; };
  double impulse = 0.0, lag_sum = 0.0, scale = 0.0;
  for (int n = 2; n <= N; ++n) {
    impulse += ext[n];
    lag_sum += lag[n + 1];
    scale += std::abs(ext[n]) + std::abs(P[n] - P[n - 1]);
  }
  const double residual = (Q(N) - Q(1)) + (P[N] - P[1]) - (impulse - lag_sum);
  std::printf(
      "[ report ] momentum on %d ranks over %d steps: residual %.3e N s (%.2e of the force scale); %lld "
      "particles\n",
      world_size(), N - 1, residual, std::abs(residual) / scale,
      static_cast<long long>(run.dem().global_count()));
  EXPECT_LE(std::abs(residual), 1e-6 * scale);
  EXPECT_EQ(run.dem().global_count(), 200);
  EXPECT_NEAR(run.particle_volume_m3(), vs, 1e-12 * vs);
}

}  // namespace
}  // namespace boycott

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  boycott::fluid::PetscSession petsc(&argc, &argv, "-no_signal_handler");
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  // One rank prints (every rank runs every test: they are collective).
  auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
  if (rank != 0) delete listeners.Release(listeners.default_result_printer());
  return RUN_ALL_TESTS();
}
