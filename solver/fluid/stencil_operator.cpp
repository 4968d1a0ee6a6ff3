#include "fluid/stencil_operator.hpp"

#include <algorithm>
#include <cstddef>
#include <exception>
#include <stdexcept>

#include "fluid/petsc_check.hpp"
#include "fluid/stencil_matrix.hpp"

namespace boycott::fluid {

namespace {

constexpr auto check = petsc_check;

PetscErrorCode shell_mult(Mat A, Vec x, Vec y) {
  void* ctx = nullptr;
  PetscCall(MatShellGetContext(A, &ctx));
  try {
    static_cast<const StencilOperator*>(ctx)->apply(x, y);
  } catch (const std::exception&) {
    return PETSC_ERR_LIB;
  }
  return 0;
}

PetscErrorCode shell_diagonal(Mat A, Vec d) {
  void* ctx = nullptr;
  PetscCall(MatShellGetContext(A, &ctx));
  const auto* op = static_cast<const StencilOperator*>(ctx);
  PetscInt n;
  PetscCall(VecGetLocalSize(d, &n));
  PetscScalar* v;
  PetscCall(VecGetArray(d, &v));
  std::copy(op->coef(0), op->coef(0) + n, v);
  PetscCall(VecRestoreArray(d, &v));
  return 0;
}

/// One row of cells: y = sum over entries in a fixed order (the same on any number of ranks).
/// lo / hi: the -y / +y entries exist.
template <bool lo, bool hi>
inline void row_product(const double* const* c, const double* __restrict x, double* __restrict y, int n,
                        std::int64_t sy, std::int64_t sz) {
  const double* __restrict c0 = c[0], * __restrict c1 = c[1], * __restrict c2 = c[2], * __restrict c3 = c[3];
  const double* __restrict c4 = c[4], * __restrict c5 = c[5], * __restrict c6 = c[6];
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) {
    double s = c0[i] * x[i] + c1[i] * x[i - 1] + c2[i] * x[i + 1];
    if constexpr (lo) s += c3[i] * x[i - sy];
    if constexpr (hi) s += c4[i] * x[i + sy];
    y[i] = s + c5[i] * x[i - sz] + c6[i] * x[i + sz];
  }
}

}  // namespace

StencilOperator::StencilOperator(DM dm) : dm_(dm), halo_(dm) {
  PetscInt xs, ys, zs, xm, ym, zm, gxs, gys, gzs, gxm, gym, gzm, my;
  DMBoundaryType bx, by, bz;
  check(DMDAGetCorners(dm, &xs, &ys, &zs, &xm, &ym, &zm), "DMDAGetCorners");
  check(DMDAGetGhostCorners(dm, &gxs, &gys, &gzs, &gxm, &gym, &gzm), "DMDAGetGhostCorners");
  check(DMDAGetInfo(dm, nullptr, nullptr, &my, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, &bx, &by,
                    &bz, nullptr),
        "DMDAGetInfo");
  // x and z are read one cell beyond the owned box on both sides, so the ghosts must be there
  if (bx != DM_BOUNDARY_PERIODIC || bz != DM_BOUNDARY_PERIODIC || xs - gxs < 1 || zs - gzs < 1)
    throw std::runtime_error("StencilOperator: needs periodic x and z with ghosts of width >= 1");
  lo_ = {xs, ys, zs}, size_ = {xm, ym, zm}, glo_ = {gxs, gys, gzs}, gsize_ = {gxm, gym, gzm};
  ny_ = my;
  wall_y_ = by != DM_BOUNDARY_PERIODIC;
  const std::size_t n = static_cast<std::size_t>(xm) * ym * zm;
  for (auto& c : coef_) c.assign(n, 0.0);
  check(DMCreateLocalVector(dm, &xl_), "DMCreateLocalVector");
  Vec g;
  check(DMGetGlobalVector(dm, &g), "DMGetGlobalVector");
  PetscInt nl, N;
  check(VecGetLocalSize(g, &nl), "VecGetLocalSize");
  check(VecGetSize(g, &N), "VecGetSize");
  check(DMRestoreGlobalVector(dm, &g), "DMRestoreGlobalVector");
  MPI_Comm comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(dm), &comm), "PetscObjectGetComm");
  check(MatCreateShell(comm, nl, nl, N, N, const_cast<StencilOperator*>(this), &shell_), "MatCreateShell");
  check(MatShellSetOperation(shell_, MATOP_MULT, reinterpret_cast<void (*)(void)>(shell_mult)),
        "MatShellSetOperation");
  check(MatShellSetOperation(shell_, MATOP_GET_DIAGONAL, reinterpret_cast<void (*)(void)>(shell_diagonal)),
        "MatShellSetOperation");
}

StencilOperator::~StencilOperator() {
  if (shell_) MatDestroy(&shell_);
  if (xl_) VecDestroy(&xl_);
}

void StencilOperator::apply(Vec x, Vec y) const {
  halo_.fill(x, xl_);
  const double* xa;
  double* ya;
  check(VecGetArrayRead(xl_, &xa), "VecGetArrayRead");
  check(VecGetArray(y, &ya), "VecGetArray");
  const std::int64_t sy = gsize_[0], sz = gsize_[0] * gsize_[1];
  const int nx = static_cast<int>(size_[0]);
  const double* c[7];
  std::int64_t o = 0;
  for (PetscInt k = lo_[2]; k < lo_[2] + size_[2]; ++k)
    for (PetscInt j = lo_[1]; j < lo_[1] + size_[1]; ++j, o += nx) {
      for (int e = 0; e < 7; ++e) c[e] = coef_[e].data() + o;
      const double* xr = xa + (k - glo_[2]) * sz + (j - glo_[1]) * sy + (lo_[0] - glo_[0]);
      const bool lo = !(wall_y_ && j == 0), hi = !(wall_y_ && j == ny_ - 1);
      if (lo && hi)
        row_product<true, true>(c, xr, ya + o, nx, sy, sz);
      else if (lo)
        row_product<true, false>(c, xr, ya + o, nx, sy, sz);
      else if (hi)
        row_product<false, true>(c, xr, ya + o, nx, sy, sz);
      else
        row_product<false, false>(c, xr, ya + o, nx, sy, sz);
    }
  check(VecRestoreArrayRead(xl_, &xa), "VecRestoreArrayRead");
  check(VecRestoreArray(y, &ya), "VecRestoreArray");
}

void StencilOperator::copy_to(Mat M, StencilMatrixWriter& W) const {
  W.begin(M);
  const std::int64_t n = static_cast<std::int64_t>(coef_[0].size());
  for (std::int64_t o = 0; o < n; ++o)
    for (int e = 0; e < 7; ++e)
      if (W.has(o, e)) W.add(o, e, coef_[e][o]);
  W.end(M);
}

}  // namespace boycott::fluid
