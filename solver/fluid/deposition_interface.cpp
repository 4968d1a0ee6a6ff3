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
  if (coupling_.open) throw std::logic_error("begin_deposition called twice");
  BC_PETSC(VecZeroEntries(coupling_.dep_solid));
  BC_PETSC(DMDAVecGetArray(layout_.da, coupling_.dep_solid, &coupling_.dep_arrays[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(coupling_.dep_S[c]));
    BC_PETSC(VecZeroEntries(coupling_.dep_K[c]));
    BC_PETSC(VecZeroEntries(coupling_.dep_KU[c]));
    BC_PETSC(DMDAVecGetArray(layout_.da, coupling_.dep_S[c], &coupling_.dep_arrays[1 + c]));
    BC_PETSC(DMDAVecGetArray(layout_.da, coupling_.dep_K[c], &coupling_.dep_arrays[4 + c]));
    BC_PETSC(DMDAVecGetArray(layout_.da, coupling_.dep_KU[c], &coupling_.dep_arrays[7 + c]));
  }
  coupling_.open = true;
}

PetscScalar*** FluidSolver::solid_fraction_local() {
  return coupling_.dep_arrays[0];
}
PetscScalar*** FluidSolver::source_local(int c) {
  return coupling_.dep_arrays[1 + c];
}
PetscScalar*** FluidSolver::drag_coefficient_local(int c) {
  return coupling_.dep_arrays[4 + c];
}
PetscScalar*** FluidSolver::drag_momentum_local(int c) {
  return coupling_.dep_arrays[7 + c];
}

void FluidSolver::end_deposition() {
  if (!coupling_.open) throw std::logic_error("end_deposition without begin_deposition");
  BC_PETSC(DMDAVecRestoreArray(layout_.da, coupling_.dep_solid, &coupling_.dep_arrays[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(DMDAVecRestoreArray(layout_.da, coupling_.dep_S[c], &coupling_.dep_arrays[1 + c]));
    BC_PETSC(DMDAVecRestoreArray(layout_.da, coupling_.dep_K[c], &coupling_.dep_arrays[4 + c]));
    BC_PETSC(DMDAVecRestoreArray(layout_.da, coupling_.dep_KU[c], &coupling_.dep_arrays[7 + c]));
  }
  coupling_.open = false;
  // alpha_f = 1 - sum of deposited solid fractions.
  BC_PETSC(VecZeroEntries(work_.R));
  BC_PETSC(DMLocalToGlobal(layout_.da, coupling_.dep_solid, ADD_VALUES, work_.R));
  BC_PETSC(VecSet(flow_.alpha[0], 1.0));
  BC_PETSC(VecAXPY(flow_.alpha[0], -1.0, work_.R));
  PetscReal amin, amax;
  BC_PETSC(VecMin(flow_.alpha[0], nullptr, &amin));
  BC_PETSC(VecMax(flow_.alpha[0], nullptr, &amax));
  if (!(amin > 0.0) || !(amax <= 1.0))
    throw PhysicsError(
        fmt::format("fluid fraction outside (0, 1] after deposition: min {:.4g}, max {:.4g}", amin, amax));
  if (!flow_.alpha_initialised && flow_.steps == 0) {
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[1]));
    BC_PETSC(VecCopy(flow_.alpha[0], flow_.alpha[2]));
  }
  flow_.alpha_initialised = true;
  for (int l = 0; l < 3; ++l) layout_.halo->fill(flow_.alpha[l], ghosts_.alpha[l]);
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(coupling_.S[c]));
    BC_PETSC(VecZeroEntries(coupling_.K[c]));
    BC_PETSC(VecZeroEntries(coupling_.KU[c]));
    BC_PETSC(DMLocalToGlobal(layout_.da, coupling_.dep_S[c], ADD_VALUES, coupling_.S[c]));
    BC_PETSC(DMLocalToGlobal(layout_.da, coupling_.dep_K[c], ADD_VALUES, coupling_.K[c]));
    BC_PETSC(DMLocalToGlobal(layout_.da, coupling_.dep_KU[c], ADD_VALUES, coupling_.KU[c]));
  }
  coupling_.armed = true;
}

void FluidSolver::clear_coupling_sources() {
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(coupling_.S[c]));
    BC_PETSC(VecZeroEntries(coupling_.K[c]));
    BC_PETSC(VecZeroEntries(coupling_.KU[c]));
  }
  coupling_.armed = false;
}

const PetscScalar* const* const* FluidSolver::read_local(int c) {
  Vec v = c < 3 ? ghosts_.U[c] : (c == 3 ? ghosts_.P : ghosts_.nut);
  BC_PETSC(DMDAVecGetArrayRead(layout_.da, v, &coupling_.read_arrays[c]));
  return coupling_.read_arrays[c];
}

void FluidSolver::restore_read(int c) {
  Vec v = c < 3 ? ghosts_.U[c] : (c == 3 ? ghosts_.P : ghosts_.nut);
  BC_PETSC(DMDAVecRestoreArrayRead(layout_.da, v, &coupling_.read_arrays[c]));
}

}  // namespace boycott::fluid
