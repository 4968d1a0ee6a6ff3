#include "fluid/stencil_operator.hpp"

#include <algorithm>
#include <cstddef>
#include <exception>
#include <stdexcept>
#include <type_traits>

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

/// The same row sum, each neighbour read from its own row: x (this row, periodic in x), ys / yn
/// (the rows at -y / +y, read where lo / hi), zb / zt (the rows in the planes below and above).
/// With `scaled`, each row's sum is multiplied by w[i] (y = diag(w) A x, the sum first).
template <bool lo, bool hi, bool scaled>
inline void row_product_rows(const double* const* c, const double* __restrict x, const double* __restrict ys,
                             const double* __restrict yn, const double* __restrict zb,
                             const double* __restrict zt, const double* __restrict w, double* __restrict y,
                             int n) {
  const double* __restrict c0 = c[0], * __restrict c1 = c[1], * __restrict c2 = c[2], * __restrict c3 = c[3];
  const double* __restrict c4 = c[4], * __restrict c5 = c[5], * __restrict c6 = c[6];
  const auto one = [&](int i, int im, int ip) {
    double s = c0[i] * x[i] + c1[i] * x[im] + c2[i] * x[ip];
    if constexpr (lo) s += c3[i] * ys[i];
    if constexpr (hi) s += c4[i] * yn[i];
    const double r = s + c5[i] * zb[i] + c6[i] * zt[i];
    if constexpr (scaled)
      y[i] = r * w[i];
    else
      y[i] = r;
  };
  // the x ends wrap (periodic x); with n = 1 or 2 both neighbours are one cell
  one(0, n - 1, n > 1 ? 1 : 0);
#pragma GCC ivdep
  for (int i = 1; i < n - 1; ++i) one(i, i - 1, i + 1);
  if (n > 1) one(n - 1, n - 2, 0);
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

// Where each rank owns whole z-planes (HaloExchange's fast path) the product reads the owned
// values in place and only the two planes beyond the slab travel: filling a ghosted copy of x
// first moved the whole vector once more per product (the copy was ~1/5 of a product's time).
// Each row's sum is the ghosted path's, term for term, so the results are the same to the bit.
void StencilOperator::apply(Vec x, Vec y) const {
  product(x, y, nullptr);
}

void StencilOperator::apply_scaled(Vec x, Vec y, Vec w) const {
  product(x, y, w);
}

void StencilOperator::product(Vec x, Vec y, Vec w) const {
  if (!halo_.fast()) {
    apply_ghosted(x, y);
    if (w) check(VecPointwiseMult(y, y, w), "VecPointwiseMult");
    return;
  }
  const double *g, *wa = nullptr;
  double* ya;
  check(VecGetArrayRead(x, &g), "VecGetArrayRead");
  check(VecGetArray(y, &ya), "VecGetArray");
  if (w) check(VecGetArrayRead(w, &wa), "VecGetArrayRead");
  const int nx = static_cast<int>(size_[0]), ny = static_cast<int>(size_[1]), nz = static_cast<int>(size_[2]);
  const std::size_t plane = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  planes_.resize(2 * plane);
  double* below = planes_.data();
  double* above = below + plane;
  halo_.boundary_planes(g, below, above);
  const double* c[7];
  std::int64_t o = 0;
  for (int k = 0; k < nz; ++k) {
    const double* P = g + static_cast<std::size_t>(k) * plane;
    const double* Pb = k > 0 ? P - plane : below;
    const double* Pt = k + 1 < nz ? P + plane : above;
    for (int j = 0; j < ny; ++j, o += nx) {
      for (int e = 0; e < 7; ++e) c[e] = coef_[e].data() + o;
      const std::size_t r = static_cast<std::size_t>(j) * nx;
      // -y / +y rows (periodic y wraps; at a wall the entry does not exist)
      const double* ys = P + static_cast<std::size_t>((j + ny - 1) % ny) * nx;
      const double* yn = P + static_cast<std::size_t>((j + 1) % ny) * nx;
      const bool lo = !(wall_y_ && j == 0), hi = !(wall_y_ && j == ny - 1);
      const auto run = [&](auto LO, auto HI, auto SCALED) {
        row_product_rows<LO.value, HI.value, SCALED.value>(c, P + r, ys, yn, Pb + r, Pt + r,
                                                           wa ? wa + o : nullptr, ya + o, nx);
      };
      const auto by_scale = [&](auto LO, auto HI) {
        if (wa)
          run(LO, HI, std::true_type{});
        else
          run(LO, HI, std::false_type{});
      };
      if (lo && hi)
        by_scale(std::true_type{}, std::true_type{});
      else if (lo)
        by_scale(std::true_type{}, std::false_type{});
      else if (hi)
        by_scale(std::false_type{}, std::true_type{});
      else
        by_scale(std::false_type{}, std::false_type{});
    }
  }
  if (w) check(VecRestoreArrayRead(w, &wa), "VecRestoreArrayRead");
  check(VecRestoreArrayRead(x, &g), "VecRestoreArrayRead");
  check(VecRestoreArray(y, &ya), "VecRestoreArray");
}

const StencilOperator* StencilOperator::of(Mat A) {
  PetscBool shell = PETSC_FALSE;
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATSHELL, &shell), "PetscObjectTypeCompare");
  if (!shell) return nullptr;
  void (*mult)(void) = nullptr;
  check(MatShellGetOperation(A, MATOP_MULT, &mult), "MatShellGetOperation");
  if (mult != reinterpret_cast<void (*)(void)>(shell_mult)) return nullptr;
  void* ctx = nullptr;
  check(MatShellGetContext(A, &ctx), "MatShellGetContext");
  return static_cast<const StencilOperator*>(ctx);
}

void StencilOperator::apply_ghosted(Vec x, Vec y) const {
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
