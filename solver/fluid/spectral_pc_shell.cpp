#include "fluid/spectral_pc_shell.hpp"

#include "fluid/petsc_check.hpp"

namespace boycott::fluid {

SpectralPcShell::SpectralPcShell(DM da, const GridSpec& g) : dm(da) {
  const MPI_Comm comm = PetscObjectComm((PetscObject)da);
  int nranks = 1;
  MPI_Comm_size(comm, &nranks);
  const int n[3] = {(int)g.n[0], (int)g.n[1], (int)g.n[2]};
  if (nranks == 1) {
    serial = std::make_unique<SpectralPoissonPreconditioner>(n[0], n[1], n[2], g.periodic[1]);
    return;
  }
  dist = std::make_unique<DistributedSpectralPoisson>(n[0], n[1], n[2], g.periodic[1], comm);
  // Laid out in FFTW's slabs (create_layout): this rank's global block is its slab.
  PetscInt xs, ys, zs, xm, ym, zm;
  BC_PETSC(DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm));
  int aligned_here = xm == n[0] && ym == n[1] && zs == dist->z_begin() && zm == dist->z_count();
  int aligned_all = 0;
  MPI_Allreduce(&aligned_here, &aligned_all, 1, MPI_INT, MPI_MIN, comm);
  aligned = aligned_all == 1;
  if (aligned) return;
  const PetscInt plane = static_cast<PetscInt>(n[0]) * n[1];
  const PetscInt count = plane * dist->z_count(), first = plane * dist->z_begin();
  BC_PETSC(DMDACreateNaturalVector(dm, &nat));
  BC_PETSC(VecCreateMPI(comm, count, PETSC_DETERMINE, &slab));
  BC_PETSC(VecDuplicate(slab, &slab_out));
  IS is;
  BC_PETSC(ISCreateStride(comm, count, first, 1, &is));
  BC_PETSC(VecScatterCreate(nat, is, slab, is, &to_slab));
  BC_PETSC(ISDestroy(&is));
}

SpectralPcShell::~SpectralPcShell() {
  if (to_slab) VecScatterDestroy(&to_slab);
  if (slab) VecDestroy(&slab);
  if (slab_out) VecDestroy(&slab_out);
  if (nat) VecDestroy(&nat);
}

void SpectralPcShell::set_coefficients(double cx, double cy, double cz) {
  if (serial) serial->set_coefficients(cx, cy, cz);
  if (dist) dist->set_coefficients(cx, cy, cz);
}

PetscErrorCode SpectralPcShell::apply(PC pc, Vec x, Vec y) {
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(pc, &ctx));
  auto& S = *static_cast<SpectralPcShell*>(ctx);
  const PetscScalar* xa;
  PetscScalar* ya;
  if (S.serial || S.aligned) {  // one rank, or FFTW's slabs: the global vector is in transform order
    PetscCall(VecGetArrayRead(x, &xa));
    PetscCall(VecGetArray(y, &ya));
    if (S.serial)
      S.serial->apply(xa, ya);
    else
      S.dist->apply(xa, ya);
    PetscCall(VecRestoreArrayRead(x, &xa));
    PetscCall(VecRestoreArray(y, &ya));
    return 0;
  }
  PetscCall(DMDAGlobalToNaturalBegin(S.dm, x, INSERT_VALUES, S.nat));
  PetscCall(DMDAGlobalToNaturalEnd(S.dm, x, INSERT_VALUES, S.nat));
  PetscCall(VecScatterBegin(S.to_slab, S.nat, S.slab, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(S.to_slab, S.nat, S.slab, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecGetArrayRead(S.slab, &xa));
  PetscCall(VecGetArray(S.slab_out, &ya));
  S.dist->apply(xa, ya);
  PetscCall(VecRestoreArrayRead(S.slab, &xa));
  PetscCall(VecRestoreArray(S.slab_out, &ya));
  PetscCall(VecScatterBegin(S.to_slab, S.slab_out, S.nat, INSERT_VALUES, SCATTER_REVERSE));
  PetscCall(VecScatterEnd(S.to_slab, S.slab_out, S.nat, INSERT_VALUES, SCATTER_REVERSE));
  PetscCall(DMDANaturalToGlobalBegin(S.dm, S.nat, INSERT_VALUES, y));
  PetscCall(DMDANaturalToGlobalEnd(S.dm, S.nat, INSERT_VALUES, y));
  return 0;
}

}  // namespace boycott::fluid
