// The coupling interface of the fluid solver: explicit momentum source, implicit drag towards a
// deposited particle velocity, ADD_VALUES deposition through ghost cells, ghosted reads, CFL
// time step, and state export/import for checkpoints.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "fluid/fluid_solver.hpp"

namespace boycott::fluid {
namespace {

FluidSettings periodic_box() {
  FluidSettings s;
  s.grid.n = {4, 4, 4};
  s.grid.length_m = {1.0, 1.0, 1.0};
  s.grid.periodic = {true, true, true};
  s.density_kg_m3 = 1000.0;
  s.viscosity_pa_s = 1e-3;
  s.dt_max_s = 1e-3;
  s.simple_tolerance = 1e-12;
  return s;
}

/// Fills a face field uniformly on the owned cells through the deposition arrays.
void deposit_uniform(FluidSolver& f, double source_z, double k_z, double ku_z) {
  const OwnedBox b = f.owned_box();
  f.begin_deposition();
  for (auto k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (auto j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (auto i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        f.source_local(2)[k][j][i] += source_z;
        f.drag_coefficient_local(2)[k][j][i] += k_z;
        f.drag_momentum_local(2)[k][j][i] += ku_z;
      }
  f.end_deposition();
}

TEST(CouplingInterface, ExplicitSourceAcceleratesFluidUniformly) {
  // rho dw/dt = S: w = S t / rho, exact for BDF2 (linear in t); the momentum solver's default
  // rtol 1e-8 is tightened here through its option prefix so that exactness shows.
  PetscOptionsSetValue(nullptr, "-momentum_ksp_rtol", "1e-14");
  FluidSolver f(periodic_box());
  PetscOptionsClearValue(nullptr, "-momentum_ksp_rtol");
  deposit_uniform(f, 2.0, 0.0, 0.0);
  for (int n = 0; n < 5; ++n) f.step(1e-3);
  // exact up to the SIMPLE tolerance (1e-12 per step, relative)
  EXPECT_NEAR(f.mean_velocity(2), 2.0 * 5e-3 / 1000.0, 1e-15);
  EXPECT_NEAR(f.max_abs_velocity(2), 1e-5, 1e-15);
}

TEST(CouplingInterface, ImplicitDragRelaxesFluidToParticleVelocity) {
  // rho dw/dt = K (u_p - w): w = u_p (1 - exp(-K t / rho)); BDF2 with K dt/rho = 0.01.
  const double up = 0.01, K = 1.0e4;  // kg/(m^3 s): K/rho = 10 1/s
  {
    FluidSolver f(periodic_box());
    deposit_uniform(f, 0.0, K, K * up);
    for (int n = 0; n < 100; ++n) f.step(1e-3);
    const double exact = up * (1.0 - std::exp(-1.0));
    EXPECT_NEAR(f.mean_velocity(2) / exact, 1.0, 1e-4);
  }
  {
    // stiff dense bed: K dt / rho = 1e4, far beyond any explicit limit; stays bounded, w -> u_p
    FluidSolver f(periodic_box());
    deposit_uniform(f, 0.0, 1e10, 1e10 * up);
    for (int n = 0; n < 3; ++n) f.step(1e-3);
    EXPECT_NEAR(f.mean_velocity(2) / up, 1.0, 1e-6);
  }
}

TEST(CouplingInterface, DepositionAddsGhostContributionsAcrossPeriodicBoundaries) {
  // A particle of solid volume fraction 0.1 (of one cell) at (0.01, 0.51, 0.99) m spread with
  // trilinear weights over the 8 surrounding cells, four of them across the periodic x and z
  // boundaries, written into ghost cells and added by the assembly.
  FluidSolver f(periodic_box());
  const double h = 0.25, x[3] = {0.01, 0.51, 0.99}, share = 0.1;
  const GhostBox g = f.ghost_box();
  const OwnedBox b = f.owned_box();
  int rank;
  MPI_Comm_rank(f.comm(), &rank);
  // the rank owning the particle's nearest cell deposits it
  const std::int64_t own[3] = {0, 2, 3};
  bool mine = true;
  for (int d = 0; d < 3; ++d) mine = mine && own[d] >= b.lo[d] && own[d] < b.lo[d] + b.size[d];
  f.begin_deposition();
  if (mine) {
    int lo[3];
    double w[3];
    for (int d = 0; d < 3; ++d) {
      const double s = x[d] / h - 0.5;
      lo[d] = static_cast<int>(std::floor(s));
      w[d] = s - lo[d];
      ASSERT_GE(lo[d], g.lo[d]);
      ASSERT_LT(lo[d] + 1, g.lo[d] + g.size[d]);
    }
    for (int c = 0; c < 8; ++c) {
      const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
      double wt = 1.0;
      for (int d = 0; d < 3; ++d) wt *= o[d] ? w[d] : 1.0 - w[d];
      f.solid_fraction_local()[lo[2] + o[2]][lo[1] + o[1]][lo[0] + o[0]] += share * wt;
    }
  }
  f.end_deposition();
  f.step(1e-3);
  const auto a = f.gather(5);
  double removed = 0.0;
  for (double v : a) removed += 1.0 - v;
  EXPECT_NEAR(removed, share, 1e-14);
  // cell (3, 1, 3) (x wrapped to the last column, y below, z in place): weights 0.46*0.46*... per axis
  const double wx = 1.0 - (0.01 / h - 0.5 - std::floor(0.01 / h - 0.5));  // weight of the wrapped x cell
  const double sy = 0.51 / h - 0.5, sz = 0.99 / h - 0.5;
  const double wy = 1.0 - (sy - std::floor(sy)), wz = 1.0 - (sz - std::floor(sz));
  EXPECT_NEAR(1.0 - a[3 + 4 * (1 + 4 * 3)], share * wx * wy * wz, 1e-14);
}

TEST(CouplingInterface, FluidFractionOutsideUnitIntervalIsRefused) {
  FluidSolver f(periodic_box());
  const OwnedBox b = f.owned_box();
  f.begin_deposition();
  f.solid_fraction_local()[b.lo[2]][b.lo[1]][b.lo[0]] += 1.0;
  EXPECT_THROW(f.end_deposition(), PhysicsError);
}

TEST(CouplingInterface, GhostedReadsSeePeriodicNeighbours) {
  FluidSolver f(periodic_box());
  f.set_velocity(2, [](double x, double, double) { return x; });
  const auto* w = f.read_local(2);
  const OwnedBox b = f.owned_box();
  // one cell to the left of the first owned column: periodic image or the neighbour rank's value
  const auto i = b.lo[0] - 1;
  const double expect = i < 0 ? 0.875 : (i + 0.5) * 0.25;
  EXPECT_DOUBLE_EQ(w[b.lo[2]][b.lo[1]][i], expect);
  f.restore_read(2);
}

TEST(AdaptiveTimeStep, CflLimitAndUpperBound) {
  FluidSettings s = periodic_box();
  s.dt_max_s = 1.0;
  FluidSolver f(s);
  f.set_velocity(2, [](double, double, double) { return 2.0; });
  EXPECT_DOUBLE_EQ(f.stable_dt(), 0.5 * 0.25 / 2.0);  // CFL 0.5 on h = 0.25 m
  s.dt_max_s = 0.01;
  FluidSolver g(s);
  g.set_velocity(2, [](double, double, double) { return 2.0; });
  EXPECT_DOUBLE_EQ(g.stable_dt(), 0.01);
}

TEST(Checkpoint, ExportImportContinuesBitwise) {
  FluidSettings s = periodic_box();
  s.grid.periodic[1] = false;
  s.body_acceleration_m_s2 = {0.0, 0.0, 1.0};
  s.target_mean_flux_z_m_s = 1e-4;
  FluidSolver a(s);
  a.set_velocity(0, [](double, double y, double z) { return 1e-3 * std::sin(6.28 * z) * y; });
  for (int n = 0; n < 3; ++n) a.step(1e-3);
  const FluidState st = a.export_state();
  for (int n = 0; n < 2; ++n) a.step(1e-3);
  FluidSolver b(s);
  b.import_state(st);
  for (int n = 0; n < 2; ++n) b.step(1e-3);
  for (int c = 0; c < 4; ++c) {
    const auto ua = a.gather(c), ub = b.gather(c);
    for (std::size_t i = 0; i < ua.size(); ++i) ASSERT_EQ(ua[i], ub[i]) << "field " << c << " index " << i;
  }
  EXPECT_EQ(a.mean_pressure_gradient_pa_m(), b.mean_pressure_gradient_pa_m());
  EXPECT_EQ(a.time_s(), b.time_s());
}

}  // namespace
}  // namespace boycott::fluid
