// StencilMatrixWriter writes the same matrix as MatSetValuesStencil: every entry of a 7-point star
// matrix on a DMDA (periodic x and z, walls or periodicity in y), including a periodic direction
// two cells long, where a row's two neighbours are the same cell and their values add. And
// StencilOperator (the matrix-free operator of the momentum and pressure systems) gives the same
// product as the AIJ matrix it copies itself into, on the same grids. Runs on PETSC_COMM_WORLD
// (one rank under ctest; under mpirun the rows are split over ranks). Where the ranks own whole
// z-planes the product reads x in place; it must give the ghosted path's values to the bit. The
// momentum solve's point Jacobi is applied in the same pass as the product: the same solution to
// the bit as the two passes.
#include <gtest/gtest.h>
#include <petscdmda.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>
#include <utility>

#include "fluid/halo_exchange.hpp"
#include "fluid/linear_solvers.hpp"
#include "fluid/stencil_matrix.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {
namespace {

/// The fluid's matrix DM: periodic x and z, walls (or periodicity) in y, star stencil of width 1.
DM make_da(PetscInt nx, PetscInt ny, PetscInt nz, bool periodic_y) {
  DM da;
  const DMBoundaryType by = periodic_y ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  EXPECT_EQ(
      DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, nx,
                   ny, nz, PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE, 1, 1, nullptr, nullptr, nullptr, &da),
      0);
  EXPECT_EQ(DMSetUp(da), 0);
  return da;
}

/// A value for (cell, entry) that differs between entries and cells.
double value(PetscInt i, PetscInt j, PetscInt k, int e) {
  return 1.0 + 0.37 * e + 0.011 * i + 0.13 * j + 1.7e-3 * k;
}

/// Largest |A - B| over all entries after filling both with the same values, one through
/// MatSetValuesStencil and one through the writer.
double max_difference(PetscInt nx, PetscInt ny, PetscInt nz, bool periodic_y) {
  DM da = make_da(nx, ny, nz, periodic_y);
  Mat A, B;
  EXPECT_EQ(DMCreateMatrix(da, &A), 0);
  EXPECT_EQ(DMCreateMatrix(da, &B), 0);
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);

  StencilMatrixWriter W(da, B);
  MatZeroEntries(A);
  W.begin(B);
  std::int64_t o = 0;
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i, ++o) {
        MatStencil row{};
        row.i = i, row.j = j, row.k = k;
        for (int e = 0; e < 7; ++e) {
          MatStencil col = row;
          if (e > 0) {
            const int d = (e - 1) / 2, s = (e % 2 == 0) ? 1 : -1;
            (d == 0 ? col.i : d == 1 ? col.j : col.k) += s;
            if (d == 1 && !periodic_y && (col.j < 0 || col.j >= ny)) continue;  // beyond a wall: no entry
          }
          const PetscScalar v = value(i, j, k, e);
          MatSetValuesStencil(A, 1, &row, 1, &col, &v, ADD_VALUES);
          W.add(o, e, v);
        }
      }
  MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY);
  MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY);
  W.end(B);
  // a second round through the writer must replace the values, not add to them
  W.begin(B);
  W.end(B);
  EXPECT_EQ(MatAXPY(B, 0.0, A, SAME_NONZERO_PATTERN), 0);
  PetscReal zero_norm;
  MatNorm(B, NORM_INFINITY, &zero_norm);
  EXPECT_EQ(zero_norm, 0.0) << "begin() must zero the values";

  // fill B again and compare
  W.begin(B);
  o = 0;
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i, ++o)
        for (int e = 0; e < 7; ++e) {
          if (e > 0 && (e - 1) / 2 == 1 && !periodic_y &&
              (j + ((e % 2 == 0) ? 1 : -1) < 0 || j + ((e % 2 == 0) ? 1 : -1) >= ny))
            continue;
          W.add(o, e, value(i, j, k, e));
        }
  W.end(B);
  MatAXPY(B, -1.0, A, SAME_NONZERO_PATTERN);
  PetscReal diff;
  MatNorm(B, NORM_INFINITY, &diff);
  PetscReal scale;
  MatNorm(A, NORM_INFINITY, &scale);
  EXPECT_GT(scale, 1.0);
  MatDestroy(&A);
  MatDestroy(&B);
  DMDestroy(&da);
  return diff;
}

TEST(StencilMatrixWriter, MatchesMatSetValuesStencilWithWallsInY) {
  EXPECT_EQ(max_difference(7, 6, 5, false), 0.0);
}

TEST(StencilMatrixWriter, MatchesMatSetValuesStencilFullyPeriodic) {
  EXPECT_EQ(max_difference(6, 4, 5, true), 0.0);
}

TEST(StencilMatrixWriter, AddsBothNeighboursWhereAPeriodicDirectionIsTwoCellsLong) {
  EXPECT_EQ(max_difference(2, 3, 4, false), 0.0);
}

// ---- StencilOperator: the matrix-free product against its AIJ copy

/// A coefficient for (cell, entry) that differs between entries and cells.
double coefficient(PetscInt i, PetscInt j, PetscInt k, int e) {
  return 1.0 + 0.37 * e + 0.011 * i - 0.13 * j + 1.7e-3 * k;
}

/// A global vector of the DM holding a smooth test field.
Vec test_vector(DM da) {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);
  Vec x;
  DMCreateGlobalVector(da, &x);
  PetscScalar*** xa;
  DMDAVecGetArray(da, x, &xa);
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i) xa[k][j][i] = std::sin(1.3 * i + 0.7 * j * j + 2.1 * k) + 0.5;
  DMDAVecRestoreArray(da, x, &xa);
  return x;
}

/// The operator's coefficients: coefficient() times (1 + wobble sin(row + entry)).
void fill_coefficients(DM da, StencilOperator& op, double wobble) {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);
  std::int64_t o = 0;
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i, ++o)
        for (int e = 0; e < 7; ++e)
          op.coef(e)[o] = coefficient(i, j, k, e) * (1.0 + wobble * std::sin(static_cast<double>(o + e)));
}

struct Result {
  double max_difference = 0.0;  ///< max |A_shell x - A_aij x| / max |A_aij x|
  double diagonal_difference = 0.0;
};

Result compare(PetscInt nx, PetscInt ny, PetscInt nz, bool periodic_y) {
  DM da = make_da(nx, ny, nz, periodic_y);
  StencilOperator op(da);
  fill_coefficients(da, op, 0.0);
  Mat B;
  EXPECT_EQ(DMCreateMatrix(da, &B), 0);
  StencilMatrixWriter W(da, B);
  op.copy_to(B, W);

  Vec x = test_vector(da), y_shell, y_aij, d_shell, d_aij;
  VecDuplicate(x, &y_shell);
  VecDuplicate(x, &y_aij);
  VecDuplicate(x, &d_shell);
  VecDuplicate(x, &d_aij);
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

// ---- StencilOperator: the in-place product on z-slabs against the ghosted one

/// Largest |apply - apply_ghosted| (0 when every value agrees to the bit) on a DMDA cut into
/// z-slabs only (the fluid's decomposition, where apply() reads x in place), ghost width 2 as the
/// momentum DM has where the grid is long enough (else 1); and whether that decomposition took
/// the in-place path.
std::pair<double, bool> in_place_against_ghosted(PetscInt nx, PetscInt ny, PetscInt nz, bool periodic_y) {
  DM da;
  const DMBoundaryType by = periodic_y ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  EXPECT_EQ(DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR,
                         nx, ny, nz, 1, 1, PETSC_DECIDE, 1, std::min({nx, ny, PetscInt{2}}), nullptr, nullptr,
                         nullptr, &da),
            0);
  EXPECT_EQ(DMSetUp(da), 0);
  StencilOperator op(da);
  fill_coefficients(da, op, 1e-3);
  Vec x = test_vector(da), y_in_place, y_ghosted;
  VecDuplicate(x, &y_in_place);
  VecDuplicate(x, &y_ghosted);
  op.apply(x, y_in_place);
  op.apply_ghosted(x, y_ghosted);
  VecAXPY(y_in_place, -1.0, y_ghosted);
  PetscReal diff;
  VecNorm(y_in_place, NORM_INFINITY, &diff);
  const bool in_place = HaloExchange(da).fast();
  for (Vec* v : {&x, &y_in_place, &y_ghosted}) VecDestroy(v);
  DMDestroy(&da);
  return {diff, in_place};
}

TEST(StencilOperator, InPlaceProductOnZSlabsIsTheGhostedOneToTheBit) {
  int ranks;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  // walls in y, periodic y, and periodic directions one and two cells long
  for (const auto& [nx, ny, periodic_y] :
       {std::tuple{7, 6, false}, std::tuple{6, 4, true}, std::tuple{2, 3, false}, std::tuple{1, 2, true}}) {
    const auto [diff, in_place] = in_place_against_ghosted(nx, ny, 3 * ranks, periodic_y);
    EXPECT_TRUE(in_place) << nx << " x " << ny;
    EXPECT_EQ(diff, 0.0) << nx << " x " << ny << (periodic_y ? ", periodic y" : ", walls in y");
  }
}

// ---- The fused product and Jacobi scaling of the momentum solves

/// A DMDA cut into z-slabs (in-place products) or left to PETSc (ghosted products on 2+ ranks),
/// with the test coefficients, a diagonally dominant operator as the momentum rows are.
struct SmallSystem {
  DM da = nullptr;
  std::unique_ptr<StencilOperator> op;
  Vec x = nullptr, w = nullptr;
  SmallSystem(bool slabs, bool periodic_y) {
    const DMBoundaryType by = periodic_y ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
    int ranks;
    MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
    const PetscInt one = slabs ? 1 : PETSC_DECIDE;
    EXPECT_EQ(
        DMDACreate3d(PETSC_COMM_WORLD, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, 7,
                     6, 4 * ranks, one, one, PETSC_DECIDE, 1, 1, nullptr, nullptr, nullptr, &da),
        0);
    EXPECT_EQ(DMSetUp(da), 0);
    PetscInt xs, ys, zs, xm, ym, zm;
    DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm);
    op = std::make_unique<StencilOperator>(da);
    x = test_vector(da);
    VecDuplicate(x, &w);
    PetscScalar*** wa;
    DMDAVecGetArray(da, w, &wa);
    std::int64_t o = 0;
    for (PetscInt k = zs; k < zs + zm; ++k)
      for (PetscInt j = ys; j < ys + ym; ++j)
        for (PetscInt i = xs; i < xs + xm; ++i, ++o) {
          for (int e = 1; e < 7; ++e) op->coef(e)[o] = -0.1 * coefficient(i, j, k, e);
          op->coef(0)[o] = 3.0 + coefficient(i, j, k, 0);
          wa[k][j][i] = 1.0 / op->coef(0)[o];
        }
    DMDAVecRestoreArray(da, w, &wa);
  }
  ~SmallSystem() {
    VecDestroy(&x);
    VecDestroy(&w);
    op.reset();
    DMDestroy(&da);
  }
};

TEST(StencilOperator, ScaledProductIsTheProductThenTheScalingToTheBit) {
  for (const bool slabs : {true, false})
    for (const bool periodic_y : {false, true}) {
      SmallSystem sys(slabs, periodic_y);
      Vec fused, apart;
      VecDuplicate(sys.x, &fused);
      VecDuplicate(sys.x, &apart);
      sys.op->apply_scaled(sys.x, fused, sys.w);
      sys.op->apply(sys.x, apart);
      VecPointwiseMult(apart, apart, sys.w);
      VecAXPY(fused, -1.0, apart);
      PetscReal diff;
      VecNorm(fused, NORM_INFINITY, &diff);
      EXPECT_EQ(diff, 0.0) << (slabs ? "z-slabs" : "PETSc's decomposition")
                           << (periodic_y ? ", periodic y" : "");
      VecDestroy(&fused);
      VecDestroy(&apart);
    }
}

TEST(StencilOperator, IsFoundBehindItsOwnShellOnly) {
  SmallSystem sys(true, false);
  EXPECT_EQ(StencilOperator::of(sys.op->mat()), sys.op.get());
  Mat aij;
  ASSERT_EQ(DMCreateMatrix(sys.da, &aij), 0);
  EXPECT_EQ(StencilOperator::of(aij), nullptr);
  MatDestroy(&aij);
}

/// y = A x through the operator, behind a MATSHELL that is not the operator's own: the momentum
/// solve's preconditioner cannot fuse it, so it multiplies and scales in two passes.
PetscErrorCode foreign_mult(Mat A, Vec x, Vec y) {
  void* ctx = nullptr;
  PetscCall(MatShellGetContext(A, &ctx));
  static_cast<const StencilOperator*>(ctx)->apply(x, y);
  return 0;
}

TEST(MomentumSolve, FusedJacobiProductsGiveTheSolutionOfTheSeparateOnesToTheBit) {
  for (const bool slabs : {true, false}) {
    SmallSystem sys(slabs, false);
    Vec inv_diag = sys.w;
    KSP ksp = create_momentum_ksp(PETSC_COMM_WORLD, &inv_diag, false);
    Mat foreign;
    PetscInt n, N;
    VecGetLocalSize(sys.x, &n);
    VecGetSize(sys.x, &N);
    MatCreateShell(PETSC_COMM_WORLD, n, n, N, N, sys.op.get(), &foreign);
    MatShellSetOperation(foreign, MATOP_MULT, reinterpret_cast<void (*)(void)>(foreign_mult));
    Vec b, x_fused, x_apart;
    VecDuplicate(sys.x, &b);
    VecDuplicate(sys.x, &x_fused);
    VecDuplicate(sys.x, &x_apart);
    sys.op->apply(sys.x, b);  // the exact solution is sys.x
    PetscInt its[2];
    for (int pass = 0; pass < 2; ++pass) {
      Vec sol = pass == 0 ? x_fused : x_apart;
      const Mat A = pass == 0 ? sys.op->mat() : foreign;
      VecSet(sol, 0.0);
      ASSERT_EQ(KSPSetOperators(ksp, A, A), 0);
      ASSERT_EQ(KSPSolve(ksp, b, sol), 0);
      KSPGetIterationNumber(ksp, &its[pass]);
    }
    EXPECT_GE(its[0], 2) << "a solve of several products";
    EXPECT_EQ(its[0], its[1]);
    VecAXPY(x_apart, -1.0, x_fused);
    PetscReal diff, err;
    VecNorm(x_apart, NORM_INFINITY, &diff);
    EXPECT_EQ(diff, 0.0) << (slabs ? "z-slabs" : "PETSc's decomposition");
    VecAXPY(x_fused, -1.0, sys.x);
    VecNorm(x_fused, NORM_INFINITY, &err);
    EXPECT_LT(err, 1e-6);
    for (Vec* v : {&b, &x_fused, &x_apart}) VecDestroy(v);
    MatDestroy(&foreign);
    KSPDestroy(&ksp);
  }
}

}  // namespace
}  // namespace boycott::fluid
