// main() for test binaries that use PETSc: PetscInitialize once for all tests.
#include <gtest/gtest.h>

#include "fluid/petsc_session.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  boycott::fluid::PetscSession petsc(&argc, &argv, "-no_signal_handler");
  return RUN_ALL_TESTS();
}
