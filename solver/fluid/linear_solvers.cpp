#include "fluid/linear_solvers.hpp"

#include <exception>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/spectral_pc_shell.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

namespace {

void configure_pressure_amg(PC pc) {
#if defined(PETSC_HAVE_HYPRE)
  BC_PETSC(PCSetType(pc, PCHYPRE));
  BC_PETSC(PCHYPRESetType(pc, "boomeramg"));
  // hypre's advice for 3-D Laplacians (HMIS coarsening, ext+i interpolation, strength 0.5,
  // 4 entries per interpolation row, one level of aggressive coarsening) in place of PETSc's
  // 2-D-minded defaults (Falgout, 0.25): setup and V-cycle are cheaper by more than the extra
  // iterations cost (bench/cfd_steps.sh: ~1180 -> ~780 ms per step). Only where the user gave
  // none of these options for this solver.
  const char* prefix = nullptr;
  BC_PETSC(PCGetOptionsPrefix(pc, &prefix));
  const std::pair<const char*, const char*> tuned[] = {{"-pc_hypre_boomeramg_coarsen_type", "HMIS"},
                                                       {"-pc_hypre_boomeramg_interp_type", "ext+i"},
                                                       {"-pc_hypre_boomeramg_strong_threshold", "0.5"},
                                                       {"-pc_hypre_boomeramg_P_max", "4"},
                                                       {"-pc_hypre_boomeramg_agg_nl", "1"}};
  for (const auto& [name, value] : tuned) {
    const std::string full = std::string("-") + (prefix ? prefix : "") + (name + 1);
    PetscBool given = PETSC_FALSE;
    BC_PETSC(PetscOptionsHasName(nullptr, nullptr, full.c_str(), &given));
    if (!given) BC_PETSC(PetscOptionsSetValue(nullptr, full.c_str(), value));
  }
#else
  BC_PETSC(PCSetType(pc, PCGAMG));
#endif
}

PetscErrorCode apply_inverse_diagonal(PC p, Vec x, Vec y) {
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(p, &ctx));
  PetscCall(VecPointwiseMult(y, x, *static_cast<Vec*>(ctx)));
  return 0;
}

// B A x in one pass where A is a StencilOperator and the side is left (BiCGStab's two products
// per iteration): the product and the Jacobi scaling were two passes over the vector, the second
// reading back what the first wrote. Same values: each row's sum times its reciprocal diagonal.
PetscErrorCode apply_inverse_diagonal_after(PC p, PCSide side, Vec x, Vec y, Vec work) {
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(p, &ctx));
  const Vec inv_diag = *static_cast<Vec*>(ctx);
  Mat A;
  PetscCall(PCGetOperators(p, &A, nullptr));
  if (side == PC_LEFT) {
    const StencilOperator* op = nullptr;
    try {
      op = StencilOperator::of(A);
      if (op) op->apply_scaled(x, y, inv_diag);
    } catch (const std::exception&) {
      return PETSC_ERR_LIB;
    }
    if (op) return 0;
    PetscCall(MatMult(A, x, work));
    PetscCall(VecPointwiseMult(y, work, inv_diag));
    return 0;
  }
  if (side == PC_RIGHT) {
    PetscCall(VecPointwiseMult(work, x, inv_diag));
    PetscCall(MatMult(A, work, y));
    return 0;
  }
  return PETSC_ERR_SUP;  // symmetric: point Jacobi has no split form here
}

}  // namespace

void set_abs_tol(KSP ksp, double abs_tol) {
  if (abs_tol < 0.0) return;
  PetscReal rtol, atol, dtol;
  PetscInt maxits;
  BC_PETSC(KSPGetTolerances(ksp, &rtol, &atol, &dtol, &maxits));
  BC_PETSC(KSPSetTolerances(ksp, rtol, abs_tol, dtol, maxits));
}

KSP create_momentum_ksp(MPI_Comm comm, Vec* inv_diag, bool relative_to_initial) {
  KSP ksp;
  BC_PETSC(KSPCreate(comm, &ksp));
  BC_PETSC(KSPSetOptionsPrefix(ksp, "momentum_"));
  BC_PETSC(KSPSetType(ksp, KSPBCGS));
  BC_PETSC(KSPSetTolerances(ksp, relative_to_initial ? 1e-2 : 1e-8, 1e-50, PETSC_DEFAULT, 1000));
  if (relative_to_initial) BC_PETSC(KSPConvergedDefaultSetUIRNorm(ksp));
  BC_PETSC(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
  // Point Jacobi: the BDF2 term makes the momentum rows strongly diagonally dominant (one or
  // two BiCGStab iterations either way), and block Jacobi/ILU refactored the matrix for every
  // solve (~110 ms per step on the bench mesh). As a shell with the reciprocal diagonal the
  // assembly already has: PCJACOBI extracted it from the matrix at every solve (2 % of a step);
  // same arithmetic, same bits. `-momentum_pc_type` replaces it.
  PC pc;
  BC_PETSC(KSPGetPC(ksp, &pc));
  BC_PETSC(PCSetType(pc, PCSHELL));
  BC_PETSC(PCShellSetContext(pc, inv_diag));
  BC_PETSC(PCShellSetApply(pc, apply_inverse_diagonal));
  BC_PETSC(PCShellSetApplyBA(pc, apply_inverse_diagonal_after));
  BC_PETSC(PCShellSetName(pc, "point Jacobi (reciprocal diagonal from the assembly)"));
  BC_PETSC(KSPSetFromOptions(ksp));
  return ksp;
}

KSP create_pressure_amg_ksp(MPI_Comm comm, const char* prefix) {
  KSP ksp;
  BC_PETSC(KSPCreate(comm, &ksp));
  BC_PETSC(KSPSetOptionsPrefix(ksp, prefix));
  // GMRES, not CG: with a packed bed at a wall (alpha_f ~ 0.45 beside 1) BoomerAMG turned out
  // not symmetric positive enough for CG (KSP_DIVERGED_INDEFINITE_PC in the demo study at 50,
  // 70 and 90 deg); GMRES converges on the same systems.
  BC_PETSC(KSPSetType(ksp, KSPGMRES));
  // 1e-2 relative per SIMPLE iteration: SIMPLE iterates until the continuity residual of the
  // momentum solution is below simple_tolerance, so an exact p' each iteration buys nothing
  // (8.5-8.75 SIMPLE iterations per bench step at 1e-8, 1e-3 and 1e-2 alike; 1e-8 costs ~3x the
  // V-cycles), and the final correction leaves 1e-2 of an already converged residual.
  BC_PETSC(KSPSetTolerances(ksp, 1e-2, 1e-50, PETSC_DEFAULT, 1000));
  PC pc;
  BC_PETSC(KSPGetPC(ksp, &pc));
  configure_pressure_amg(pc);
  BC_PETSC(KSPSetFromOptions(ksp));
  return ksp;
}

KSP create_pressure_ksp(MPI_Comm comm, SpectralPcShell* spectral, double spectral_rtol) {
  if (!spectral) return create_pressure_amg_ksp(comm, "pressure_");
  KSP ksp;
  BC_PETSC(KSPCreate(comm, &ksp));
  BC_PETSC(KSPSetOptionsPrefix(ksp, "pressure_"));
  PC pc;
  BC_PETSC(KSPGetPC(ksp, &pc));
  BC_PETSC(PCSetType(pc, PCSHELL));
  BC_PETSC(PCShellSetContext(pc, spectral));
  BC_PETSC(PCShellSetApply(pc, SpectralPcShell::apply));
  BC_PETSC(PCShellSetName(pc, "spectral constant-coefficient Poisson (FFT in x, z)"));
  BC_PETSC(KSPSetTolerances(ksp, spectral_rtol, 1e-50, PETSC_DEFAULT, 1000));
  // Flexible GMRES keeps the preconditioned directions, so a solve of n iterations applies the
  // preconditioner n times; left-preconditioned GMRES also applies it to the initial residual
  // (n + 1), and an application (two FFTs) is the largest part of a solve. Same iteration
  // counts on the bench (PISO 6.0, SIMPLE 16.6 against 17.6 per step); its test is on the true
  // residual instead of the preconditioned one.
  BC_PETSC(KSPSetType(ksp, KSPFGMRES));
  BC_PETSC(KSPSetFromOptions(ksp));
  return ksp;
}

PressureSolveResult solve_pressure(MPI_Comm comm, KSP main, KSP* fallback, const std::function<Mat()>& aij,
                                   Vec b, Vec x, double abs_tol) {
  PressureSolveResult res;
  BC_PETSC(VecZeroEntries(x));
  set_abs_tol(main, abs_tol);
  // A failed solve (or a PETSc error inside the preconditioner) is redone by the multigrid:
  // BoomerAMG broke down once at 90 deg in the demo study after 1.5 s, when it was the main
  // solver. Counted, so a run shows how often.
  KSPConvergedReason reason = KSP_DIVERGED_PC_FAILED;
  BC_PETSC(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));  // no traceback: handled below
  const PetscErrorCode solve_err = KSPSolve(main, b, x);
  BC_PETSC(PetscPopErrorHandler());
  if (!solve_err) BC_PETSC(KSPGetConvergedReason(main, &reason));
  int failed = (solve_err || reason < 0) ? 1 : 0, any_failed = 0;
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, comm);
  KSP used = main;
  if (any_failed) {
    if (!*fallback) *fallback = create_pressure_amg_ksp(comm, "pressure_fallback_");
    set_abs_tol(*fallback, abs_tol);
    const Mat A = aij();
    BC_PETSC(KSPSetOperators(*fallback, A, A));
    BC_PETSC(VecZeroEntries(x));
    BC_PETSC(KSPSolve(*fallback, b, x));
    BC_PETSC(KSPGetConvergedReason(*fallback, &reason));
    if (reason < 0)
      throw PhysicsError(
          fmt::format("pressure solve diverged: reason {} (also with the fallback solver)", (int)reason));
    res.used_fallback = true;
    used = *fallback;
  }
  BC_PETSC(KSPGetIterationNumber(used, &res.iterations));
  return res;
}

}  // namespace boycott::fluid
