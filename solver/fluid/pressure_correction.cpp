// The pressure correction of SIMPLE and PISO: continuity residual, the correction equation
// (alpha_f D on the faces), its solve, and the velocity and pressure update.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/linear_solvers.hpp"
#include "fluid/log_events.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/spectral_pc_shell.hpp"
#include "fluid/staggering.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

double FluidSolver::continuity_residual(double dt, double c0, double c1, double c2, Vec Rv) {
  const LogScope log_scope(fluid_events().continuity);
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  PetscScalar ***u[3], ***al[3], ***R;
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.U[d], &u[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.alpha[l], &al[l]));
  BC_PETSC(DMDAVecGetArray(layout_.da, Rv, &R));
  auto flux = [&](int d, int qi, int qj, int qk) -> double {
    if (wall && d == 1 && (qj <= 0 || qj >= n1)) return 0.0;
    const double af = 0.5 * (al[0][qk][qj][qi] + al[0][qk - kE[d][2]][qj - kE[d][1]][qi - kE[d][0]]);
    return af * u[d][qk][qj][qi];
  };
  double rmax = 0.0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        double r = (c0 * al[0][k][j][i] - c1 * al[1][k][j][i] + c2 * al[2][k][j][i]) / dt;
        for (int d = 0; d < 3; ++d)
          r += (flux(d, i + kE[d][0], j + kE[d][1], k + kE[d][2]) - flux(d, i, j, k)) / h[d];
        R[k][j][i] = r;
        rmax = std::max(rmax, std::abs(r));
      }
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.U[d], &u[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.alpha[l], &al[l]));
  BC_PETSC(DMDAVecRestoreArray(layout_.da, Rv, &R));
  double gmax;
  MPI_Allreduce(&rmax, &gmax, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return gmax;
}

void FluidSolver::assemble_pressure() {
  const LogScope log_scope(fluid_events().pressure_assembly);
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  for (int d = 0; d < 3; ++d) layout_.halo->fill(work_.D[d], ghosts_.D[d]);
  PetscScalar ***D[3], ***al;
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.D[d], &D[d]));
  BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.alpha[0], &al));
  double* Ae[7];
  for (int e = 0; e < 7; ++e) Ae[e] = ops_.pressure->coef(e);
  // coefficient a_f D / h^2 of the lower d-face of cell Q (0 on walls)
  auto coef = [&](int d, int qi, int qj, int qk) -> double {
    if (wall && d == 1 && (qj <= 0 || qj >= n1)) return 0.0;
    const double af = 0.5 * (al[qk][qj][qi] + al[qk - kE[d][2]][qj - kE[d][1]][qi - kE[d][0]]);
    return af * D[d][qk][qj][qi] / (h[d] * h[d]);
  };
  std::int64_t o = 0;
  // Mean face coefficient per direction (walls excluded), for the spectral preconditioner.
  double csum[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i, ++o) {
        double diag = 0.0;
        for (int d = 0; d < 3; ++d) {
          const double cm = coef(d, i, j, k);
          const double cp = coef(d, i + kE[d][0], j + kE[d][1], k + kE[d][2]);
          if (cm != 0.0) {
            csum[d] += cm;
            csum[3 + d] += 1.0;
          }
          diag += cm + cp;
          Ae[1 + 2 * d][o] = -cm;
          Ae[2 + 2 * d][o] = -cp;
        }
        Ae[0][o] = diag;
      }
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.D[d], &D[d]));
  BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.alpha[0], &al));
  if (solvers_.spectral_pc) {
    double gsum[6];
    MPI_Allreduce(csum, gsum, 6, MPI_DOUBLE, MPI_SUM, comm_);
    double c[3];
    for (int d = 0; d < 3; ++d) c[d] = gsum[3 + d] > 0.0 ? gsum[d] / gsum[3 + d] : 0.0;
    solvers_.spectral_pc->set_coefficients(c[0], c[1], c[2]);
  }
  const Mat A = ops_.pressure_needs_aij ? aij_copy(*ops_.pressure, &ops_.pressure_aij) : ops_.pressure->mat();
  BC_PETSC(KSPSetOperators(solvers_.pressure, A, A));
}

void FluidSolver::correct(Vec pcorr) {
  const LogScope log_scope(fluid_events().correction);
  const auto& g = s_.grid;
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  layout_.halo->fill(pcorr, ghosts_.pc);
  PetscScalar ***pc, ***U[3], ***D[3];
  BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.pc, &pc));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecGetArray(layout_.da, flow_.U[d], &U[d]));
    BC_PETSC(DMDAVecGetArray(layout_.da, work_.D[d], &D[d]));
  }
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i)
        for (int d = 0; d < 3; ++d) {
          if (d == 1 && wall && j == 0) continue;
          U[d][k][j][i] -=
              D[d][k][j][i] * (pc[k][j][i] - pc[k - kE[d][2]][j - kE[d][1]][i - kE[d][0]]) / h[d];
        }
  BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.pc, &pc));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecRestoreArray(layout_.da, flow_.U[d], &U[d]));
    BC_PETSC(DMDAVecRestoreArray(layout_.da, work_.D[d], &D[d]));
  }
  // SIMPLEC: the pressure correction is consistent with the velocity correction and applied whole
  BC_PETSC(VecAXPY(flow_.P, 1.0, pcorr));
}

void FluidSolver::solve_pressure_correction(StepReport& rep, bool refresh_ghosts) {
  BC_PETSC(VecScale(work_.R, -1.0));
  BC_PETSC(MatNullSpaceRemove(solvers_.null_space, work_.R));
  const auto res = solve_pressure(
      comm_, solvers_.pressure, &solvers_.pressure_fallback,
      [this] { return aij_copy(*ops_.pressure, &ops_.pressure_aij); }, work_.R, work_.pc,
      solvers_.user_pressure_atol ? -1.0 : solvers_.pressure_abs_tol);
  if (res.used_fallback) ++counters_.pressure_fallbacks;
  rep.pressure_krylov_iterations += (int)res.iterations;
  correct(work_.pc);
  if (refresh_ghosts) update_flow_ghosts();
}

double FluidSolver::relative_continuity_residual(double dt, const double c[3], double umax) {
  const auto& g = s_.grid;
  const double hmin = std::min({g.dx(0), g.dx(1), g.dx(2)});
  for (int cc = 0; cc < 3; ++cc) layout_.halo->fill(flow_.U[cc], ghosts_.U[cc]);
  const double rmax = continuity_residual(dt, c[0], c[1], c[2], work_.R);
  const double uref = std::max(
      {umax, std::abs(std::isfinite(s_.target_mean_flux_z_m_s) ? s_.target_mean_flux_z_m_s : 0.0), 1e-30});
  if (!std::isfinite(rmax) || !std::isfinite(umax))
    throw PhysicsError(fmt::format("fluid velocity became NaN at t = {:.6g} s", flow_.time_s));
  // The pressure correction need not reduce a residual far below what SIMPLE's test accepts
  // (rmax h / U < simple_tolerance): without a floor, a residual at round-off level (a flow
  // that already satisfies continuity, as plane Poiseuille does) can never be reduced by the
  // relative tolerance and the solve fails after its iteration limit.
  // Nor below the round-off of the residual's own terms: the BDF2 sum (c0 a - c1 a + c2 a)/dt
  // of a constant alpha_f is not exactly zero, and a fluid at rest has no velocity scale at all.
  const double noise = 16.0 * std::numeric_limits<double>::epsilon() *
                       std::sqrt(static_cast<double>(g.cell_count())) * (c[0] + c[1] + c[2]) / dt;
  solvers_.pressure_abs_tol = std::max(1e-4 * s_.simple_tolerance * uref / hmin, noise);
  return rmax * hmin / uref;
}

}  // namespace boycott::fluid
