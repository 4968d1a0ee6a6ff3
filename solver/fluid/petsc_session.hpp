#pragma once
// RAII for PetscInitialize/PetscFinalize (which also initialise and finalise MPI). One per
// process; `extra_options` are PETSc command-line options such as "-pressure_ksp_type cg".
#include <string>
#include <vector>

namespace boycott::fluid {

class PetscSession {
 public:
  PetscSession(int* argc, char*** argv, const std::string& extra_options = "");
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
  static bool active();
  /// The options given that nothing read (a misspelt `-pressure_ksp_typ`), for a warning.
  static std::vector<std::string> unused_options();
};

}  // namespace boycott::fluid
