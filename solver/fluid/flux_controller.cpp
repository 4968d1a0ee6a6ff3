// The flux controller: the uniform mean pressure gradient G (Pa/m) that holds the box mean
// of alpha_f w at its target (Eq. 25's zero slurry flux, or a bulk velocity).
#include "fluid/fluid_solver.hpp"

#include <cmath>

#include "fluid/petsc_check.hpp"

namespace boycott::fluid {

void FluidSolver::apply_flux_controller() {
  if (!std::isfinite(s_.target_mean_flux_z_m_s)) return;
  const OwnedBox b = owned_box();
  PetscScalar ***w, ***al, ***Dz;
  BC_PETSC(DMDAVecGetArray(layout_.da, flow_.U[2], &w));
  BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.alpha[0], &al));
  BC_PETSC(DMDAVecGetArray(layout_.da, work_.D[2], &Dz));
  double loc[2] = {0.0, 0.0};  // sum a_f w, sum a_f D
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        const double af = 0.5 * (al[k][j][i] + al[k - 1][j][i]);
        loc[0] += af * w[k][j][i];
        loc[1] += af * Dz[k][j][i];
      }
  double glob[2];
  MPI_Allreduce(loc, glob, 2, MPI_DOUBLE, MPI_SUM, comm_);
  const double ncell = static_cast<double>(s_.grid.cell_count());
  const double q = glob[0] / ncell, m = glob[1] / ncell;
  // w responds to G through the SIMPLE coefficient: w' = -D_z dG, so mean(a w)' = -mean(a D) dG.
  const double dG = (q - s_.target_mean_flux_z_m_s) / m;
  flow_.G_pa_m += dG;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) w[k][j][i] -= Dz[k][j][i] * dG;
  BC_PETSC(DMDAVecRestoreArray(layout_.da, flow_.U[2], &w));
  BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.alpha[0], &al));
  BC_PETSC(DMDAVecRestoreArray(layout_.da, work_.D[2], &Dz));
}

double FluidSolver::mean_flux_z() const {
  const OwnedBox b = owned_box();
  PetscScalar ***w, ***al;
  DMDAVecGetArray(layout_.da, flow_.U[2], &w);
  DMDAVecGetArray(layout_.da, ghosts_.alpha[0], &al);
  double loc = 0.0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i)
        loc += 0.5 * (al[k][j][i] + al[k - 1][j][i]) * w[k][j][i];
  DMDAVecRestoreArray(layout_.da, flow_.U[2], &w);
  DMDAVecRestoreArray(layout_.da, ghosts_.alpha[0], &al);
  double glob;
  MPI_Allreduce(&loc, &glob, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return glob / static_cast<double>(s_.grid.cell_count());
}

}  // namespace boycott::fluid
