#pragma once
// The fluid step's linear solvers, each set up in one place:
//   momentum_   BiCGStab with the assembly's reciprocal diagonal as point Jacobi;
//   pressure_   FGMRES with the spectral preconditioner (spectral_pc_shell.hpp), or GMRES with
//               an algebraic multigrid when the user names -pressure_pc_type;
//   pressure_fallback_  GMRES with the same multigrid set-up, which redoes a failed pressure
//               solve.
// Every choice can be changed with PETSc options under these prefixes.
#include <mpi.h>
#include <petscksp.h>

#include <functional>

namespace boycott::fluid {

struct SpectralPcShell;

/// The momentum KSP; its point-Jacobi shell reads the reciprocal diagonal from *inv_diag at
/// every application (the solve in progress sets it). `-momentum_pc_type` replaces the shell.
/// Its relative tolerance is 1e-8 of |b|, or with `relative_to_initial` 1e-2 of the initial
/// residual (the caller then sets an absolute floor per solve with set_abs_tol).
KSP create_momentum_ksp(MPI_Comm comm, Vec* inv_diag, bool relative_to_initial);

/// Sets the absolute tolerance of `ksp`, keeping its other tolerances; nothing when abs_tol < 0.
void set_abs_tol(KSP ksp, double abs_tol);

/// The pressure KSP: with `spectral` its PCSHELL (FGMRES to `spectral_rtol`), otherwise the
/// multigrid of create_pressure_amg_ksp under the prefix "pressure_".
KSP create_pressure_ksp(MPI_Comm comm, SpectralPcShell* spectral, double spectral_rtol);

/// GMRES (relative tolerance 1e-2) with BoomerAMG, tuned for 3-D Laplacians, under `prefix`;
/// GAMG where PETSc was built without hypre. BoomerAMG on every rank count: its set-up is
/// deterministic, so a run (and a resumed run) repeats bit for bit whether or not it needed a
/// fallback (GAMG's set-up is not: a resumed run differed in the last bits with it).
KSP create_pressure_amg_ksp(MPI_Comm comm, const char* prefix);

struct PressureSolveResult {
  PetscInt iterations = 0;
  bool used_fallback = false;
};

/// Solves main x = b (x starts at zero). When the solve fails on any rank (diverged, or a PETSc
/// error inside the preconditioner), redoes it with *fallback, created on first use with the
/// operator aij() (the assembled copy an AMG needs). abs_tol (1/s), unless negative, replaces
/// the absolute tolerance of both solvers. Throws PhysicsError when the fallback fails too.
PressureSolveResult solve_pressure(MPI_Comm comm, KSP main, KSP* fallback, const std::function<Mat()>& aij,
                                   Vec b, Vec x, double abs_tol);

}  // namespace boycott::fluid
