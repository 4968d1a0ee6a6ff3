#include "fluid/petsc_session.hpp"

#include <petscsys.h>

#include <stdexcept>

namespace boycott::fluid {

namespace {
bool g_active = false;
}

PetscSession::PetscSession(int* argc, char*** argv, const std::string& extra_options) {
  if (PetscInitialize(argc, argv, nullptr, nullptr) != 0) throw std::runtime_error("PetscInitialize failed");
  if (!extra_options.empty() && PetscOptionsInsertString(nullptr, extra_options.c_str()) != 0)
    throw std::runtime_error("bad PETSc options: " + extra_options);
  g_active = true;
}

PetscSession::~PetscSession() {
  g_active = false;
  PetscFinalize();
}

bool PetscSession::active() {
  return g_active;
}

}  // namespace boycott::fluid
