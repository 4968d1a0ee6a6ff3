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
  for (int c = 0; c < 3; ++c) {
    for (Vec* v :
         {&flow_.U[c], &flow_.Un[c], &flow_.Unm1[c], &flow_.alpha[c], &D_[c], &S_[c], &K_[c], &KU_[c],
          &inv_diag_[c], &Ul_[c], &alphal_[c], &Dl_[c], &dep_S_[c], &dep_K_[c], &dep_KU_[c], &Fl_[c]})
      vd(*v);
  }
  for (Vec* v : {&flow_.P, &flow_.nut, &rhs_, &sol_, &R_, &pc_, &Pl_, &nutl_, &pcl_, &dep_solid_, &nuel_})
    vd(*v);
  if (solvers_.null_space) MatNullSpaceDestroy(&solvers_.null_space);
  if (solvers_.momentum) KSPDestroy(&solvers_.momentum);
  if (solvers_.pressure) KSPDestroy(&solvers_.pressure);
  solvers_.spectral_pc.reset();  // its vectors and scatter before the DM
  if (solvers_.pressure_fallback) KSPDestroy(&solvers_.pressure_fallback);
  if (A_) MatDestroy(&A_);
  for (int c = 0; c < 3; ++c) {
    opm_[c].reset();
    vd(bm_[c]);
  }
  vd(P_asm_);
  if (Ap_) MatDestroy(&Ap_);
  opA_.reset();
  opP_.reset();
  halo_.reset();
  if (dam_) DMDestroy(&dam_);
  if (da_) DMDestroy(&da_);
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
                        nullptr, z_slabs.empty() ? nullptr : z_slabs.data(), &da_));
  BC_PETSC(DMSetUp(da_));
  halo_ = std::make_unique<HaloExchange>(da_);
  const PetscInt *lx, *ly, *lz;
  PetscInt mx, my, mz;
  BC_PETSC(DMDAGetInfo(da_, nullptr, nullptr, nullptr, nullptr, &mx, &my, &mz, nullptr, nullptr, nullptr,
                       nullptr, nullptr, nullptr));
  BC_PETSC(DMDAGetOwnershipRanges(da_, &lx, &ly, &lz));
  // Same ownership, 7-point star of width 1: the matrices need no more than that.
  BC_PETSC(DMDACreate3d(comm_, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR,
                        (PetscInt)g.n[0], (PetscInt)g.n[1], (PetscInt)g.n[2], mx, my, mz, 1, 1, lx, ly, lz,
                        &dam_));
  BC_PETSC(DMSetUp(dam_));
  // Both systems are applied matrix-free (stencil_operator.hpp); an AIJ copy is made only for a
  // preconditioner that needs the entries.
  opA_ = std::make_unique<StencilOperator>(dam_);
  opP_ = std::make_unique<StencilOperator>(dam_);
  PetscBool user_momentum_pc = PETSC_FALSE;
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-momentum_pc_type", &user_momentum_pc));
  momentum_aij_ = user_momentum_pc;
  pressure_aij_ = user_pc;

  auto gv = [&](Vec* v) { BC_PETSC(DMCreateGlobalVector(da_, v)); };
  auto lv = [&](Vec* v) { BC_PETSC(DMCreateLocalVector(da_, v)); };
  for (int c = 0; c < 3; ++c) {
    for (Vec* v : {&flow_.U[c], &flow_.Un[c], &flow_.Unm1[c], &flow_.alpha[c], &D_[c], &S_[c], &K_[c],
                   &KU_[c], &inv_diag_[c]})
      gv(v);
    for (Vec* v : {&Ul_[c], &alphal_[c], &Dl_[c], &dep_S_[c], &dep_K_[c], &dep_KU_[c], &Fl_[c]}) lv(v);
    BC_PETSC(VecSet(flow_.alpha[c], 1.0));
  }
  for (Vec* v : {&flow_.P, &flow_.nut, &rhs_, &sol_, &R_, &pc_}) gv(v);
  for (Vec* v : {&Pl_, &nutl_, &pcl_, &dep_solid_, &nuel_}) lv(v);

  solvers_.momentum = create_momentum_ksp(comm_, &jacobi_inv_diag_, inexact_inner_solves());
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-momentum_ksp_atol", &solvers_.user_momentum_atol));
  // The spectral preconditioner unless the user names another (-pressure_pc_type).
  if (!user_pc) solvers_.spectral_pc = std::make_unique<SpectralPcShell>(dam_, g);
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
  BC_PETSC(MatSetNullSpace(opP_->mat(), solvers_.null_space));
  update_ghosts();
}

Mat FluidSolver::aij_copy(const StencilOperator& op, Mat* M) {
  if (!*M) {
    BC_PETSC(DMCreateMatrix(dam_, M));
    // Every rank writes only its own rows (StencilMatrixWriter): without this, each assembly of
    // an MPIAIJ matrix still set up the communication of off-process entries.
    BC_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    BC_PETSC(MatSetOption(*M, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE));
    if (M == &Ap_) BC_PETSC(MatSetNullSpace(*M, solvers_.null_space));
    if (!writer_) writer_ = std::make_unique<StencilMatrixWriter>(dam_, *M);
  }
  op.copy_to(*M, *writer_);
  return *M;
}

OwnedBox FluidSolver::owned_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da_, &xs, &ys, &zs, &xm, &ym, &zm);
  return OwnedBox{{xs, ys, zs}, {xm, ym, zm}};
}

GhostBox FluidSolver::ghost_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetGhostCorners(da_, &xs, &ys, &zs, &xm, &ym, &zm);
  return GhostBox{{xs, ys, zs}, {xm, ym, zm}};
}

void FluidSolver::update_ghosts() {
  for (int c = 0; c < 3; ++c) halo_->fill(flow_.alpha[c], alphal_[c]);
  halo_->fill(flow_.nut, nutl_);
  update_flow_ghosts();
}

// Within a step alpha_f and nu_t are fixed; only u and p change (a ghost fill of the bench mesh
// cost ~0.3 ms with DMGlobalToLocal then, and a SIMPLE step did ~90 of them).
void FluidSolver::update_flow_ghosts() {
  for (int c = 0; c < 3; ++c) halo_->fill(flow_.U[c], Ul_[c]);
  halo_->fill(flow_.P, Pl_);
}

}  // namespace boycott::fluid
