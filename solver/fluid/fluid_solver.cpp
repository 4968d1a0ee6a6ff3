// FluidSolver's construction: the DMDA layout (FFTW's z-slabs on several ranks), vectors,
// operators and linear solvers, and the ghost fills. The step is in simple_piso.cpp.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/linear_solvers.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/spectral_pc_shell.hpp"
#include "fluid/stencil_matrix.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

FluidSolver::FluidSolver(const FluidSettings& s, MPI_Comm comm) : s_(s), comm_(comm) {
  create_layout();
}

FluidSolver::~FluidSolver() {
  auto vd = [](Vec& v) {
    if (v) VecDestroy(&v);
  };
  for (int c = 0; c < 3; ++c)
    for (Vec* v :
         {&flow_.U[c], &flow_.Un[c], &flow_.Unm1[c], &flow_.alpha[c], &work_.D[c], &work_.inv_diag[c],
          &ghosts_.U[c], &ghosts_.alpha[c], &ghosts_.D[c], &ghosts_.F[c], &coupling_.S[c], &coupling_.K[c],
          &coupling_.KU[c], &coupling_.dep_S[c], &coupling_.dep_K[c], &coupling_.dep_KU[c]})
      vd(*v);
  for (Vec* v : {&flow_.P, &flow_.nut, &work_.rhs, &work_.sol, &work_.R, &work_.pc, &ghosts_.P, &ghosts_.nut,
                 &ghosts_.pc, &ghosts_.nue, &coupling_.dep_solid})
    vd(*v);
  if (solvers_.null_space) MatNullSpaceDestroy(&solvers_.null_space);
  if (solvers_.momentum) KSPDestroy(&solvers_.momentum);
  if (solvers_.pressure) KSPDestroy(&solvers_.pressure);
  solvers_.spectral_pc.reset();  // its vectors and scatter before the DM
  if (solvers_.pressure_fallback) KSPDestroy(&solvers_.pressure_fallback);
  if (ops_.momentum_aij) MatDestroy(&ops_.momentum_aij);
  if (ops_.pressure_aij) MatDestroy(&ops_.pressure_aij);
  for (int c = 0; c < 3; ++c) {
    ops_.frozen[c].reset();
    vd(ops_.frozen_rhs[c]);
  }
  vd(ops_.frozen_pressure);
  ops_.momentum.reset();
  ops_.pressure.reset();
  layout_.halo.reset();
  if (layout_.dam) DMDestroy(&layout_.dam);
  if (layout_.da) DMDestroy(&layout_.da);
}

void FluidSolver::create_layout() {
  const auto& g = s_.grid;
  for (int d = 0; d < 3; ++d)
    if (g.n[d] < 2)
      throw InputError(fmt::format("fluid grid needs at least 2 cells per direction (got {})", g.n[d]));
  const DMBoundaryType by = g.periodic[1] ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  // With the spectral pressure preconditioner on several ranks, the grid is cut into FFTW's
  // slabs of whole z-planes: the global vectors are then stored in the transform's own order and
  // an application needs no scatter (with PETSc's own cut it needed four, which made it slower
  // on 2 ranks than on one). Every rank needs at least the ghost width (2) of planes.
  int nranks = 1;
  MPI_Comm_size(comm_, &nranks);
  PetscBool user_pc = PETSC_FALSE;
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-pressure_pc_type", &user_pc));
  std::vector<PetscInt> z_slabs;
  // The slabs also with a user's -pressure_pc_type: the coupling decomposes particles by them.
  if (nranks > 1) {
    for (int c : DistributedSpectralPoisson::z_slab_counts((int)g.n[0], (int)g.n[1], (int)g.n[2], comm_))
      z_slabs.push_back(c);
    if (std::any_of(z_slabs.begin(), z_slabs.end(), [](PetscInt c) { return c < 2; })) z_slabs.clear();
  }
  const PetscInt pz = z_slabs.empty() ? PETSC_DECIDE : nranks, pxy = z_slabs.empty() ? PETSC_DECIDE : 1;
  BC_PETSC(DMDACreate3d(comm_, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_BOX,
                        (PetscInt)g.n[0], (PetscInt)g.n[1], (PetscInt)g.n[2], pxy, pxy, pz, 1, 2, nullptr,
                        nullptr, z_slabs.empty() ? nullptr : z_slabs.data(), &layout_.da));
  BC_PETSC(DMSetUp(layout_.da));
  layout_.halo = std::make_unique<HaloExchange>(layout_.da);
  const PetscInt *lx, *ly, *lz;
  PetscInt mx, my, mz;
  BC_PETSC(DMDAGetInfo(layout_.da, nullptr, nullptr, nullptr, nullptr, &mx, &my, &mz, nullptr, nullptr,
                       nullptr, nullptr, nullptr, nullptr));
  BC_PETSC(DMDAGetOwnershipRanges(layout_.da, &lx, &ly, &lz));
  // Same ownership, 7-point star of width 1: the matrices need no more than that.
  BC_PETSC(DMDACreate3d(comm_, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR,
                        (PetscInt)g.n[0], (PetscInt)g.n[1], (PetscInt)g.n[2], mx, my, mz, 1, 1, lx, ly, lz,
                        &layout_.dam));
  BC_PETSC(DMSetUp(layout_.dam));
  // Both systems are applied matrix-free (stencil_operator.hpp); an AIJ copy is made only for a
  // preconditioner that needs the entries.
  ops_.momentum = std::make_unique<StencilOperator>(layout_.dam);
  ops_.pressure = std::make_unique<StencilOperator>(layout_.dam);
  PetscBool user_momentum_pc = PETSC_FALSE;
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-momentum_pc_type", &user_momentum_pc));
  ops_.momentum_needs_aij = user_momentum_pc;
  ops_.pressure_needs_aij = user_pc;

  auto gv = [&](Vec* v) { BC_PETSC(DMCreateGlobalVector(layout_.da, v)); };
  auto lv = [&](Vec* v) { BC_PETSC(DMCreateLocalVector(layout_.da, v)); };
  for (int c = 0; c < 3; ++c) {
    for (Vec* v : {&flow_.U[c], &flow_.Un[c], &flow_.Unm1[c], &flow_.alpha[c], &work_.D[c], &coupling_.S[c],
                   &coupling_.K[c], &coupling_.KU[c], &work_.inv_diag[c]})
      gv(v);
    for (Vec* v : {&ghosts_.U[c], &ghosts_.alpha[c], &ghosts_.D[c], &coupling_.dep_S[c], &coupling_.dep_K[c],
                   &coupling_.dep_KU[c], &ghosts_.F[c]})
      lv(v);
    BC_PETSC(VecSet(flow_.alpha[c], 1.0));
  }
  for (Vec* v : {&flow_.P, &flow_.nut, &work_.rhs, &work_.sol, &work_.R, &work_.pc}) gv(v);
  for (Vec* v : {&ghosts_.P, &ghosts_.nut, &ghosts_.pc, &coupling_.dep_solid, &ghosts_.nue}) lv(v);

  solvers_.momentum = create_momentum_ksp(comm_, &work_.jacobi_inv_diag, inexact_inner_solves());
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-momentum_ksp_atol", &solvers_.user_momentum_atol));
  // The spectral preconditioner unless the user names another (-pressure_pc_type).
  if (!user_pc) solvers_.spectral_pc = std::make_unique<SpectralPcShell>(layout_.dam, g);
  // With the spectral preconditioner a tighter solve than the multigrid's is cheap (about one
  // Krylov iteration per decade). With one correction per SIMPLE iteration it saves iterations
  // (5.8 -> 5.0 per step on the fluid bench at 1e-3 against 1e-2; 1e-4: 5.0); with two it does
  // not (4.0 at both on the bench, 7.6 at both in the developed full-size case, where 1e-2 takes
  // 26 % fewer pressure Krylov iterations). PISO is not iterated: 1e-3.
  solvers_.pressure =
      create_pressure_ksp(comm_, solvers_.spectral_pc.get(), inexact_inner_solves() ? 1e-2 : 1e-3);
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-pressure_ksp_atol", &solvers_.user_pressure_atol));
  // Periodic x, z and walls (or periodicity) in y: pure Neumann, the constant is the null space.
  BC_PETSC(MatNullSpaceCreate(comm_, PETSC_TRUE, 0, nullptr, &solvers_.null_space));
  BC_PETSC(MatSetNullSpace(ops_.pressure->mat(), solvers_.null_space));
  update_ghosts();
}

Mat FluidSolver::aij_copy(const StencilOperator& op, Mat* M) {
  if (!*M) {
    BC_PETSC(DMCreateMatrix(layout_.dam, M));
    // Every rank writes only its own rows (StencilMatrixWriter): without this, each assembly of
    // an MPIAIJ matrix still set up the communication of off-process entries.
    BC_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    BC_PETSC(MatSetOption(*M, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE));
    if (M == &ops_.pressure_aij) BC_PETSC(MatSetNullSpace(*M, solvers_.null_space));
    if (!ops_.writer) ops_.writer = std::make_unique<StencilMatrixWriter>(layout_.dam, *M);
  }
  op.copy_to(*M, *ops_.writer);
  return *M;
}

OwnedBox FluidSolver::owned_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(layout_.da, &xs, &ys, &zs, &xm, &ym, &zm);
  return OwnedBox{{xs, ys, zs}, {xm, ym, zm}};
}

GhostBox FluidSolver::ghost_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetGhostCorners(layout_.da, &xs, &ys, &zs, &xm, &ym, &zm);
  return GhostBox{{xs, ys, zs}, {xm, ym, zm}};
}

void FluidSolver::update_ghosts() {
  for (int c = 0; c < 3; ++c) layout_.halo->fill(flow_.alpha[c], ghosts_.alpha[c]);
  layout_.halo->fill(flow_.nut, ghosts_.nut);
  update_flow_ghosts();
}

// Within a step alpha_f and nu_t are fixed; only u and p change (a ghost fill of the bench mesh
// cost ~0.3 ms with DMGlobalToLocal then, and a SIMPLE step did ~90 of them).
void FluidSolver::update_flow_ghosts() {
  for (int c = 0; c < 3; ++c) layout_.halo->fill(flow_.U[c], ghosts_.U[c]);
  layout_.halo->fill(flow_.P, ghosts_.P);
}

}  // namespace boycott::fluid
