// What the coupling writes into and reads from the fluid: ghosted deposition arrays (solid
// fraction, explicit source, implicit drag), their assembly into alpha_f and the momentum
// sources, and read access to the ghosted flow fields.
#include "fluid/fluid_solver.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/petsc_check.hpp"

namespace boycott::fluid {

void FluidSolver::begin_deposition() {
  if (deposition_open_) throw std::logic_error("begin_deposition called twice");
  BC_PETSC(VecZeroEntries(dep_solid_));
  BC_PETSC(DMDAVecGetArray(da_, dep_solid_, &dep_arrays_[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(dep_S_[c]));
    BC_PETSC(VecZeroEntries(dep_K_[c]));
    BC_PETSC(VecZeroEntries(dep_KU_[c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_S_[c], &dep_arrays_[1 + c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_K_[c], &dep_arrays_[4 + c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_KU_[c], &dep_arrays_[7 + c]));
  }
  deposition_open_ = true;
}

PetscScalar*** FluidSolver::solid_fraction_local() {
  return dep_arrays_[0];
}
PetscScalar*** FluidSolver::source_local(int c) {
  return dep_arrays_[1 + c];
}
PetscScalar*** FluidSolver::drag_coefficient_local(int c) {
  return dep_arrays_[4 + c];
}
PetscScalar*** FluidSolver::drag_momentum_local(int c) {
  return dep_arrays_[7 + c];
}

void FluidSolver::end_deposition() {
  if (!deposition_open_) throw std::logic_error("end_deposition without begin_deposition");
  BC_PETSC(DMDAVecRestoreArray(da_, dep_solid_, &dep_arrays_[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(DMDAVecRestoreArray(da_, dep_S_[c], &dep_arrays_[1 + c]));
    BC_PETSC(DMDAVecRestoreArray(da_, dep_K_[c], &dep_arrays_[4 + c]));
    BC_PETSC(DMDAVecRestoreArray(da_, dep_KU_[c], &dep_arrays_[7 + c]));
  }
  deposition_open_ = false;
  // alpha_f = 1 - sum of deposited solid fractions.
  BC_PETSC(VecZeroEntries(R_));
  BC_PETSC(DMLocalToGlobal(da_, dep_solid_, ADD_VALUES, R_));
  BC_PETSC(VecSet(flow_.alpha[0], 1.0));
  BC_PETSC(VecAXPY(flow_.alpha[0], -1.0, R_));
  PetscReal amin, amax;
  BC_PETSC(VecMin(flow_.alpha[0], nullptr, &amin));
  BC_PETSC(VecMax(flow_.alpha[0], nullptr, &amax));
  if (!(amin > 0.0) || !(amax <= 1.0))
    throw PhysicsError(
        fmt::format("fluid fraction outside (0, 1] after deposition: min {:.4g}, max {:.4g}", amin, amax));
  if (!alpha_initialised_ && flow_.steps == 0) {
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[1]));
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[2]));
  }
  alpha_initialised_ = true;
  for (int l = 0; l < 3; ++l) halo_->fill(flow_.alpha[l], alphal_[l]);
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(S_[c]));
    BC_PETSC(VecZeroEntries(K_[c]));
    BC_PETSC(VecZeroEntries(KU_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_S_[c], ADD_VALUES, S_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_K_[c], ADD_VALUES, K_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_KU_[c], ADD_VALUES, KU_[c]));
  }
  coupling_armed_ = true;
}

void FluidSolver::clear_coupling_sources() {
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(S_[c]));
    BC_PETSC(VecZeroEntries(K_[c]));
    BC_PETSC(VecZeroEntries(KU_[c]));
  }
  coupling_armed_ = false;
}

const PetscScalar* const* const* FluidSolver::read_local(int c) {
  Vec v = c < 3 ? Ul_[c] : (c == 3 ? Pl_ : nutl_);
  BC_PETSC(DMDAVecGetArrayRead(da_, v, &read_arrays_[c]));
  return read_arrays_[c];
}

void FluidSolver::restore_read(int c) {
  Vec v = c < 3 ? Ul_[c] : (c == 3 ? Pl_ : nutl_);
  BC_PETSC(DMDAVecRestoreArrayRead(da_, v, &read_arrays_[c]));
}

}  // namespace boycott::fluid
