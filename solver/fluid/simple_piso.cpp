// One fluid time step: BDF2 weights, the CFL limit, and the two pressure-velocity couplings,
// SIMPLE(C) iterated to its tolerance and PISO with its correctors.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/linear_solvers.hpp"
#include "fluid/log_events.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

namespace {

/// Variable-step BDF2 weights: (c0 y^{n+1} - c1 y^n + c2 y^{n-1}) / dt with w = dt/dt_prev,
/// c0 = (1 + 2w)/(1 + w), c1 = 1 + w, c2 = w^2/(1 + w); BDF1 when there is no previous step.
void bdf_weights(double dt, double dt_prev, double c[3]) {
  if (dt_prev <= 0.0) {
    c[0] = 1.0, c[1] = 1.0, c[2] = 0.0;
    return;
  }
  const double w = dt / dt_prev;
  c[0] = (1.0 + 2.0 * w) / (1.0 + w);
  c[1] = 1.0 + w;
  c[2] = w * w / (1.0 + w);
}

}  // namespace

double FluidSolver::stable_dt() const {
  double rate = 0.0;  // max_c |u_c| / h_c, 1/s
  for (int c = 0; c < 3; ++c) rate = std::max(rate, max_abs_velocity(c) / s_.grid.dx(c));
  if (rate <= 0.0) return s_.dt_max_s;
  return std::min(s_.dt_max_s, s_.cfl_max / rate);
}

void FluidSolver::keep_momentum_operators() {
  if (ops_.frozen[0]) return;
  for (int cc = 0; cc < 3; ++cc) {
    ops_.frozen[cc] = std::make_unique<StencilOperator>(layout_.dam);
    BC_PETSC(DMCreateGlobalVector(layout_.da, &ops_.frozen_rhs[cc]));
  }
  BC_PETSC(DMCreateGlobalVector(layout_.da, &ops_.frozen_pressure));
}

// SIMPLE's iteration error, once the flow has developed, is the neighbour term that the
// correction leaves out (SIMPLEC assumes a cell's neighbours move as it does); with the
// CFL-limited convection, neighbour coefficients are a sizable part of the diagonal and the
// continuity residual falls by only ~2.8x per iteration (13 iterations per step in the
// full-size base case). A further corrector (a sweep of the frozen momentum equations at the
// corrected pressure, then a pressure correction) removes much of that term for the price of a
// pressure solve, without the momentum assembly and Krylov solves of another iteration. The
// convergence test is unchanged: it reads the momentum solution of each iteration.
void FluidSolver::step_simple(double dt, const double c[3], StepReport& rep) {
  const double tol = s_.simple_tolerance;
  const int correctors = s_.simple_correctors;
  if (correctors > 1) keep_momentum_operators();
  for (int it = 0; it < s_.simple_max_iterations; ++it) {
    const bool first = it == 0;
    const double G_asm = flow_.G_pa_m;
    if (correctors > 1) BC_PETSC(VecCopy(flow_.P, ops_.frozen_pressure));
    // max |u* - u| and max |u*| over the components: one pass each and one reduction for all
    double loc[2] = {0.0, 0.0};
    compute_face_fluxes();
    for (int cc = 0; cc < 3; ++cc) {
      StencilOperator& A = correctors > 1 ? *ops_.frozen[cc] : *ops_.momentum;
      assemble_momentum(cc, dt, c[0], c[1], c[2], first, A);
      if (correctors > 1) BC_PETSC(VecCopy(work_.rhs, ops_.frozen_rhs[cc]));
      solve_momentum(cc, A, rep);
      // the new iterate (in work_.sol) replaces the old one in flow_.U in the pass that measures the change
      const double* un;
      double* u;
      PetscInt n;
      BC_PETSC(VecGetLocalSize(flow_.U[cc], &n));
      BC_PETSC(VecGetArrayRead(work_.sol, &un));
      BC_PETSC(VecGetArray(flow_.U[cc], &u));
      double d = loc[0], m = loc[1];
      bool nan = false;
      for (PetscInt q = 0; q < n; ++q) {
        d = std::max(d, std::abs(un[q] - u[q]));
        m = std::max(m, std::abs(un[q]));
        nan |= std::isnan(un[q]);
        u[q] = un[q];
      }
      // std::max drops a NaN (and MPI's MAX need not keep one): a NaN velocity counts as +inf,
      // which the continuity check below reports
      const double inf = std::numeric_limits<double>::infinity();
      loc[0] = nan ? inf : d, loc[1] = nan ? inf : m;
      BC_PETSC(VecRestoreArrayRead(work_.sol, &un));
      BC_PETSC(VecRestoreArray(flow_.U[cc], &u));
    }
    double glob[2];
    MPI_Allreduce(loc, glob, 2, MPI_DOUBLE, MPI_MAX, comm_);
    const double du = glob[0], umax = glob[1];
    double flux_err = 0.0;
    if (std::isfinite(s_.target_mean_flux_z_m_s)) {
      const double q0 = mean_flux_z();
      flux_err = std::abs(q0 - s_.target_mean_flux_z_m_s) /
                 std::max({std::abs(s_.target_mean_flux_z_m_s), umax, 1e-30});
      apply_flux_controller();
    }
    rep.continuity_residual = relative_continuity_residual(dt, c, umax);
    const double uref = std::max(
        {umax, std::abs(std::isfinite(s_.target_mean_flux_z_m_s) ? s_.target_mean_flux_z_m_s : 0.0), 1e-30});
    const double dvel = du / uref;
    if (first) assemble_pressure();
    const bool done = rep.continuity_residual < tol && dvel < tol && flux_err < tol;
    // between correctors nothing reads the ghosts (the sweep works on global vectors and the
    // continuity residual refreshes u's)
    solve_pressure_correction(rep, done || correctors == 1);
    rep.simple_iterations = it + 1;
    if (done) {
      rep.converged = true;
      break;
    }
    for (int k = 1; k < correctors; ++k) {
      momentum_sweep(G_asm);
      if (std::isfinite(s_.target_mean_flux_z_m_s)) apply_flux_controller();
      // the iteration's max |u*| scales the pressure solve's floor as well as a new maximum would
      // (three fewer norms and reductions per corrector)
      relative_continuity_residual(dt, c, umax);
      solve_pressure_correction(rep, k + 1 == correctors);
    }
  }
}

// PISO (Issa 1986) beside SIMPLE: one momentum solve per component with the face fluxes of the
// last step, then `piso_correctors` pressure corrections without re-assembly. Corrector k > 1
// first moves the velocity by one Jacobi sweep of the frozen momentum equations at the corrected
// pressure (u += (b(p) - A u) / a_P, which is Issa's neighbour term sum a_nb u'_nb / a_P), then
// corrects it with the same (SIMPLEC) coefficient D as SIMPLE. Nothing is iterated to a
// tolerance: the step costs one momentum round and `piso_correctors` pressure solves instead of
// ~5 of each, and its difference from SIMPLE is what tests and the work-precision study report.
void FluidSolver::step_piso(double dt, const double c[3], StepReport& rep) {
  keep_momentum_operators();
  // The equations are linearised once, about u^n + (dt/dt_prev)(u^n - u^(n-1)): the face fluxes,
  // QUICK's deferred correction and the transposed stress are then O(dt^2) from their values
  // at u^(n+1), which keeps the step second order in time (about u^n it would be first order).
  if (flow_.steps > 0) {
    const double r = dt / flow_.dt_prev_s;
    for (int cc = 0; cc < 3; ++cc)
      BC_PETSC(VecAXPBYPCZ(flow_.U[cc], 1.0 + r, -r, 0.0, flow_.Un[cc], flow_.Unm1[cc]));
    update_flow_ghosts();
  }
  compute_face_fluxes();
  BC_PETSC(VecCopy(flow_.P, ops_.frozen_pressure));
  const double G_asm = flow_.G_pa_m;
  for (int cc = 0; cc < 3; ++cc) {
    assemble_momentum(cc, dt, c[0], c[1], c[2], true, *ops_.frozen[cc]);
    BC_PETSC(VecCopy(work_.rhs, ops_.frozen_rhs[cc]));
    solve_momentum(cc, *ops_.frozen[cc], rep);
    BC_PETSC(VecCopy(work_.sol, flow_.U[cc]));
  }
  if (std::isfinite(s_.target_mean_flux_z_m_s)) apply_flux_controller();
  for (int k = 0; k < s_.piso_correctors; ++k) {
    if (k > 0) {
      momentum_sweep(G_asm);
      if (std::isfinite(s_.target_mean_flux_z_m_s)) apply_flux_controller();
    }
    rep.continuity_residual = relative_continuity_residual(dt, c, max_abs_velocity_all());
    if (k == 0) assemble_pressure();
    // Between correctors nothing reads the ghosts (the sweep works on global vectors and the
    // continuity residual refreshes u's); after the last one the coupling reads them.
    const bool last = k + 1 == s_.piso_correctors;
    solve_pressure_correction(rep, last && !std::isfinite(s_.target_mean_flux_z_m_s));
  }
  // The corrections moved the mean flux a little (mean(a_f D_z dp'/dz) is not zero where alpha_f
  // varies); the controller's response w' = -D_z dG is linear, so one more application holds
  // the target exactly, at the cost of a continuity defect of order dG d(a_f D_z)/dz.
  if (std::isfinite(s_.target_mean_flux_z_m_s)) {
    apply_flux_controller();
    update_flow_ghosts();
  }
  rep.simple_iterations = s_.piso_correctors;
  rep.converged = true;
}

void FluidSolver::momentum_sweep(double G_asm) {
  const LogScope log_scope(fluid_events().momentum_sweep);
  // p - p_asm, ghosted: the pressure the frozen right-hand sides b were assembled with
  BC_PETSC(VecWAXPY(work_.pc, -1.0, ops_.frozen_pressure, flow_.P));
  layout_.halo->fill(work_.pc, ghosts_.pc);
  const auto& g = s_.grid;
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const double inv_rho = 1.0 / s_.density_kg_m3;
  const double *al, *dp;
  BC_PETSC(VecGetArrayRead(ghosts_.alpha[0], &al));
  BC_PETSC(VecGetArrayRead(ghosts_.pc, &dp));
  for (int cc = 0; cc < 3; ++cc) {
    ops_.frozen[cc]->apply(flow_.U[cc], work_.sol);  // A u
    const double *Au, *bv, *aP;
    double* u;
    BC_PETSC(VecGetArrayRead(work_.sol, &Au));
    BC_PETSC(VecGetArrayRead(ops_.frozen_rhs[cc], &bv));
    aP = ops_.frozen[cc]->coef(0);
    BC_PETSC(VecGetArray(flow_.U[cc], &u));
    const std::int64_t oc = off[cc];
    const double igrad = inv_rho / g.dx(cc);
    // the mean gradient G acts like a pressure gradient on w: its change since the assembly too
    const double dbody = cc == 2 ? -(flow_.G_pa_m - G_asm) * inv_rho : 0.0;
    std::int64_t o = 0;
    for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
      for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j) {
        const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
        const int nx = (int)b.size[0];
        if (cc == 1 && wall && j == 0) {  // identity rows: v = 0 on the wall
          o += nx;
          continue;
        }
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const std::int64_t P = P0 + i;
          const double a1 = 0.5 * (al[P] + al[P - oc]);
          const double r = bv[o + i] - Au[o + i] + a1 * (dbody - (dp[P] - dp[P - oc]) * igrad);
          u[o + i] += r / aP[o + i];
        }
        o += nx;
      }
    BC_PETSC(VecRestoreArrayRead(work_.sol, &Au));
    BC_PETSC(VecRestoreArrayRead(ops_.frozen_rhs[cc], &bv));
    BC_PETSC(VecRestoreArray(flow_.U[cc], &u));
  }
  BC_PETSC(VecRestoreArrayRead(ghosts_.alpha[0], &al));
  BC_PETSC(VecRestoreArrayRead(ghosts_.pc, &dp));
}

void FluidSolver::solve_momentum(int cc, const StencilOperator& op, StepReport& rep) {
  work_.jacobi_inv_diag = work_.inv_diag[cc];
  const Mat A = ops_.momentum_needs_aij ? aij_copy(op, &ops_.momentum_aij) : op.mat();
  BC_PETSC(KSPSetOperators(solvers_.momentum, A, A));
  if (inexact_inner_solves() && !solvers_.user_momentum_atol) {
    // 1e-2 of the initial residual, but never further than the 1e-8 of |b| of the exact solves:
    // at a fixed point the initial residual is round-off, which no solve can reduce 100x. The
    // floor is in the norm the test uses: BiCGStab's left-preconditioned one, |b / a_P| with the
    // Jacobi shell. The norm type is resolved by the first set-up and fixed from then on.
    if (solvers_.momentum_floor_jacobi < 0) {
      KSPNormType norm;
      BC_PETSC(KSPSetUp(solvers_.momentum));
      BC_PETSC(KSPGetNormType(solvers_.momentum, &norm));
      solvers_.momentum_floor_jacobi = norm == KSP_NORM_PRECONDITIONED && !ops_.momentum_needs_aij ? 1 : 0;
    }
    if (solvers_.momentum_floor_jacobi == 1)
      BC_PETSC(VecPointwiseMult(work_.sol, work_.rhs, work_.inv_diag[cc]));
    else
      BC_PETSC(VecCopy(work_.rhs, work_.sol));
    PetscReal bnorm;
    BC_PETSC(VecNorm(work_.sol, NORM_2, &bnorm));
    set_abs_tol(solvers_.momentum, 1e-8 * bnorm);
  }
  BC_PETSC(VecCopy(flow_.U[cc], work_.sol));
  BC_PETSC(KSPSolve(solvers_.momentum, work_.rhs, work_.sol));
  KSPConvergedReason reason;
  BC_PETSC(KSPGetConvergedReason(solvers_.momentum, &reason));
  if (reason < 0)
    throw PhysicsError(fmt::format("momentum solve (component {}) diverged: reason {}", cc, (int)reason));
  PetscInt its;
  BC_PETSC(KSPGetIterationNumber(solvers_.momentum, &its));
  rep.momentum_krylov_iterations += (int)its;
}

double FluidSolver::max_abs_velocity_all() const {
  double umax = 0.0;
  for (int cc = 0; cc < 3; ++cc) umax = std::max(umax, max_abs_velocity(cc));
  return umax;
}

StepReport FluidSolver::step(double dt) {
  if (coupling_.open) throw std::logic_error("step() inside begin/end_deposition");
  if (!(dt > 0.0)) throw std::invalid_argument("step: dt must be > 0");
  StepReport rep;
  rep.dt_s = dt;
  double c[3];
  bdf_weights(dt, flow_.steps > 0 ? flow_.dt_prev_s : 0.0, c);
  for (int l = 0; l < 3; ++l) layout_.halo->fill(flow_.alpha[l], ghosts_.alpha[l]);
  compute_subgrid_viscosity();  // also refreshes nu_t's ghosts
  compute_effective_viscosity();
  update_flow_ghosts();
  if (s_.piso) {
    step_piso(dt, c, rep);
  } else {
    step_simple(dt, c, rep);
  }
  rep.mean_pressure_gradient_pa_m = flow_.G_pa_m;
  // continuity defect of the accepted fields (for diagnostics and tests)
  counters_.last_dt_s = dt;
  counters_.last_defect = continuity_residual(dt, c[0], c[1], c[2], work_.R);
  // rotate time levels
  for (int cc = 0; cc < 3; ++cc) {
    BC_PETSC(VecCopy(flow_.Un[cc], flow_.Unm1[cc]));
    BC_PETSC(VecCopy(flow_.U[cc], flow_.Un[cc]));
  }
  BC_PETSC(VecCopy(flow_.alpha[1], flow_.alpha[2]));
  BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[1]));
  for (int l = 1; l < 3; ++l) layout_.halo->fill(flow_.alpha[l], ghosts_.alpha[l]);
  flow_.time_s += dt;
  flow_.dt_prev_s = dt;
  ++flow_.steps;
  return rep;
}

}  // namespace boycott::fluid
