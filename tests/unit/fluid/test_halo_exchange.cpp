// HaloExchange fills a ghosted local vector with exactly what DMGlobalToLocal puts there: on the
// fluid's layouts (whole z-planes per rank; box stencil of width 2 with y walls, star of width 1,
// periodic y) through its block copies, and on a layout that splits x through the fallback.
// Runs on PETSC_COMM_WORLD (one rank under ctest; 2 and 3 ranks under mpirun).
#include <gtest/gtest.h>
#include <petscdmda.h>

#include <cmath>

#include "fluid/halo_exchange.hpp"

namespace boycott::fluid {
namespace {

struct Layout {
  PetscInt nx, ny, nz;
  bool periodic_y;
  DMDAStencilType stencil;
  PetscInt width;
  bool split_x;  ///< let PETSc cut x too (not whole z-planes per rank)
};

/// Largest |HaloExchange - DMGlobalToLocal| over the local vector (ghosts included), and whether
/// the block-copy path ran.
std::pair<double, bool> compare(const Layout& L) {
  int size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  const DMBoundaryType by = L.periodic_y ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  const PetscInt pxy = L.split_x ? PETSC_DECIDE : 1, pz = L.split_x ? PETSC_DECIDE : size;
  DM da;
  EXPECT_EQ(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, L.stencil, L.nx,
                         L.ny, L.nz, pxy, pxy, pz, 1, L.width, nullptr, nullptr, nullptr, &da),
            0);
  EXPECT_EQ(DMSetUp(da), 0);
  HaloExchange halo(da);
  Vec g, expected, got;
  DMCreateGlobalVector(da, &g);
  DMCreateLocalVector(da, &expected);
  DMCreateLocalVector(da, &got);
  PetscScalar*** a;
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);
  DMDAVecGetArray(da, g, &a);
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i)
        a[k][j][i] = 1.0 + i + 100.0 * j + 10000.0 * k;  // unique per cell
  DMDAVecRestoreArray(da, g, &a);
  // the same background in both, so ghosts neither fills (corners of a star stencil) compare equal
  VecSet(expected, -1.0);
  VecSet(got, -1.0);
  DMGlobalToLocal(da, g, INSERT_VALUES, expected);
  halo.fill(g, got);
  if (L.stencil == DMDA_STENCIL_STAR && halo.fast()) {
    // DMDA leaves the corner ghosts of a star stencil unset; the block copy fills them. Compare
    // only what DMDA fills: mark the unset ones in `expected` and copy them over.
    const double* e;
    double* q;
    PetscInt n;
    VecGetLocalSize(expected, &n);
    VecGetArrayRead(expected, &e);
    VecGetArray(got, &q);
    for (PetscInt m = 0; m < n; ++m)
      if (e[m] == -1.0) q[m] = -1.0;
    VecRestoreArrayRead(expected, &e);
    VecRestoreArray(got, &q);
  }
  VecAXPY(got, -1.0, expected);
  PetscReal diff;
  VecNorm(got, NORM_INFINITY, &diff);
  double global_diff;
  MPI_Allreduce(&diff, &global_diff, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  const bool fast = halo.fast();
  for (Vec* v : {&g, &expected, &got}) VecDestroy(v);
  DMDestroy(&da);
  return {global_diff, fast};
}

TEST(HaloExchange, FillsLikeDMGlobalToLocalOnTheFluidGrid) {
  const auto [diff, fast] = compare({20, 6, 12, false, DMDA_STENCIL_BOX, 2, false});
  EXPECT_TRUE(fast);
  EXPECT_EQ(diff, 0.0);
}

TEST(HaloExchange, FillsLikeDMGlobalToLocalOnTheMatrixGrid) {
  const auto [diff, fast] = compare({20, 6, 12, false, DMDA_STENCIL_STAR, 1, false});
  EXPECT_TRUE(fast);
  EXPECT_EQ(diff, 0.0);
}

TEST(HaloExchange, FillsLikeDMGlobalToLocalWithPeriodicY) {
  const auto [diff, fast] = compare({8, 5, 12, true, DMDA_STENCIL_BOX, 2, false});
  EXPECT_TRUE(fast);
  EXPECT_EQ(diff, 0.0);
}

TEST(HaloExchange, FallsBackWhereXIsSplit) {
  int size;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  const auto [diff, fast] = compare({24, 6, 2, false, DMDA_STENCIL_BOX, 2, true});
  if (size > 1) {
    EXPECT_FALSE(fast);
  }
  EXPECT_EQ(diff, 0.0);
}

}  // namespace
}  // namespace boycott::fluid
