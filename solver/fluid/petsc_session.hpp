#pragma once
// RAII for PetscInitialize/PetscFinalize (which also initialise and finalise MPI). One per
// process; `extra_options` are PETSc command-line options such as "-pressure_ksp_type cg".
#include <string>

namespace boycott::fluid {

class PetscSession {
 public:
  PetscSession(int* argc, char*** argv, const std::string& extra_options = "");
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
  static bool active();
};

}  // namespace boycott::fluid
