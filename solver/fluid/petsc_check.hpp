#pragma once
// PETSc error codes as exceptions, for the fluid library's own sources.
#include <petscsys.h>

#include <stdexcept>

#include <fmt/format.h>

namespace boycott::fluid {

inline void petsc_check(PetscErrorCode ierr, const char* what) {
  if (ierr != 0)
    throw std::runtime_error(fmt::format("PETSc call failed ({}): {}", static_cast<int>(ierr), what));
}

}  // namespace boycott::fluid

/// Checks a PETSc call, naming it in the exception.
#define BC_PETSC(call) ::boycott::fluid::petsc_check((call), #call)
