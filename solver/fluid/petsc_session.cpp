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

std::vector<std::string> PetscSession::unused_options() {
  std::vector<std::string> out;
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  if (!g_active || PetscOptionsLeftGet(nullptr, &n, &names, &values) != 0) return out;
  // -no_signal_handler is the program's own, inserted after PETSc read its start-up options.
  for (PetscInt i = 0; i < n; ++i)
    if (std::string(names[i]) != "no_signal_handler") out.push_back(std::string("-") + names[i]);
  PetscOptionsLeftRestore(nullptr, &n, &names, &values);
  return out;
}

}  // namespace boycott::fluid
