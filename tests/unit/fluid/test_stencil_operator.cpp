// StencilOperator (the matrix-free 7-point operator of the momentum and pressure systems) gives
// the same product as the AIJ matrix it copies itself into: walls or periodicity in y, and a
// periodic direction two cells long, where a row's two neighbours are the same cell. Runs on
// PETSC_COMM_WORLD (one rank under ctest; under mpirun the rows are split over ranks).
#include <gtest/gtest.h>
#include <petscdmda.h>

#include <algorithm>
#include <cmath>

#include "fluid/stencil_matrix.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {
namespace {

/// A coefficient for (cell, entry) that differs between entries and cells.
double value(PetscInt i, PetscInt j, PetscInt k, int e) { return 1.0 + 0.37 * e + 0.011 * i - 0.13 * j + 1.7e-3 * k; }

struct Result {
  double max_difference = 0.0;  ///< max |A_shell x - A_aij x| / max |A_aij x|
  double diagonal_difference = 0.0;
};

Result compare(PetscInt nx, PetscInt ny, PetscInt nz, bool periodic_y) {
  DM da;
  const DMBoundaryType by = periodic_y ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  EXPECT_EQ(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, nx, ny, nz,
                         PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE, 1, 1, nullptr, nullptr, nullptr, &da),
            0);
  EXPECT_EQ(DMSetUp(da), 0);
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);
  StencilOperator op(da);
  std::int64_t o = 0;
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i, ++o)
        for (int e = 0; e < 7; ++e) op.coef(e)[o] = value(i, j, k, e);
  Mat B;
  EXPECT_EQ(DMCreateMatrix(da, &B), 0);
  StencilMatrixWriter W(da, B);
  op.copy_to(B, W);

  Vec x, y_shell, y_aij, d_shell, d_aij;
  DMCreateGlobalVector(da, &x);
  VecDuplicate(x, &y_shell);
  VecDuplicate(x, &y_aij);
  VecDuplicate(x, &d_shell);
  VecDuplicate(x, &d_aij);
  PetscScalar*** xa;
  DMDAVecGetArray(da, x, &xa);
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i) xa[k][j][i] = std::sin(1.3 * i + 0.7 * j * j + 2.1 * k) + 0.5;
  DMDAVecRestoreArray(da, x, &xa);
  EXPECT_EQ(MatMult(op.mat(), x, y_shell), 0);
  EXPECT_EQ(MatMult(B, x, y_aij), 0);
  PetscReal scale, diff, dscale, ddiff;
  VecNorm(y_aij, NORM_INFINITY, &scale);
  VecAXPY(y_shell, -1.0, y_aij);
  VecNorm(y_shell, NORM_INFINITY, &diff);
  EXPECT_GT(scale, 1.0);
  EXPECT_EQ(MatGetDiagonal(op.mat(), d_shell), 0);
  MatGetDiagonal(B, d_aij);
  VecNorm(d_aij, NORM_INFINITY, &dscale);
  VecAXPY(d_shell, -1.0, d_aij);
  VecNorm(d_shell, NORM_INFINITY, &ddiff);
  for (Vec* v : {&x, &y_shell, &y_aij, &d_shell, &d_aij}) VecDestroy(v);
  MatDestroy(&B);
  DMDestroy(&da);
  return {diff / scale, ddiff / dscale};
}

// The two products differ only in summation order: a few ulps of the row sums.
constexpr double kRoundoff = 1e-14;

TEST(StencilOperator, MatchesItsAijCopyWithWallsInY) {
  const Result r = compare(7, 6, 5, false);
  EXPECT_LT(r.max_difference, kRoundoff);
  EXPECT_EQ(r.diagonal_difference, 0.0);
}

TEST(StencilOperator, MatchesItsAijCopyFullyPeriodic) {
  const Result r = compare(6, 4, 5, true);
  EXPECT_LT(r.max_difference, kRoundoff);
  EXPECT_EQ(r.diagonal_difference, 0.0);
}

TEST(StencilOperator, AddsBothNeighboursWhereAPeriodicDirectionIsTwoCellsLong) {
  const Result r = compare(2, 3, 4, false);
  EXPECT_LT(r.max_difference, kRoundoff);
}

}  // namespace
}  // namespace boycott::fluid
