#pragma once
// Void-fraction kernels: how one particle's volume and force are shared among grid cells, and,
// transposed, how grid values are read at the particle (section II C of the paper:
// with dx = 1 mm and d = 0.6 mm a one-cell deposit is noisy, so the default spreads
// each particle over its neighbourhood).
//
// A kernel is separable: the weight of cell (i,j,k) is wx(i) wy(j) wz(k), each 1-D set summing
// to 1. Face weights (for the staggered velocity, pressure-gradient and force fields) are derived
// from the cell weights: face f, between cells f-1 and f, gets (w(f-1) + w(f))/2. That is exactly
// the transpose of how the fluid solver forms alpha_f on a face (the mean of its two cells), so a
// force computed from a face field with these weights cancels the fluid's own alpha-weighted term
// to round-off (momentum test). Away from the walls it reproduces linear fields exactly, like
// trilinear sampling; near a wall the folded weights ignore the no-slip rule, so sampling with
// them ("kernel") is not exact there (sampling.hpp has the wall-aware "trilinear").
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::coupling {

enum class KernelKind {
  cell,                ///< all weight in the cell holding the centre (noisy; comparisons)
  trilinear,           ///< cloud-in-cell: linear in each direction, 2 cells per direction
  trilinear_smoothed,  ///< trilinear convolved with a one-cell box (quadratic B-spline), 3 cells
};

inline KernelKind kernel_from_name(const std::string& s) {
  if (s == "cell") return KernelKind::cell;
  if (s == "trilinear") return KernelKind::trilinear;
  if (s == "trilinear_smoothed") return KernelKind::trilinear_smoothed;
  throw InputError(fmt::format("numerics.void_fraction_kernel = \"{}\": not a kernel of the coupling", s));
}

/// 1-D weights over the contiguous index range [first, first + n). Indices may lie outside
/// [0, ncell) in a periodic direction (the caller wraps them); in a wall-bounded direction the
/// part of the kernel beyond a wall is folded back (mirrored) so the weights stay in the domain
/// and still sum to 1.
struct Weights1D {
  int first = 0;
  int n = 0;
  double w[4] = {0.0, 0.0, 0.0, 0.0};
};

/// Weights of a particle at coordinate x (m, from the domain's lower edge), cell size h (m).
inline Weights1D cell_weights(KernelKind kind, double x, double h, int ncell, bool walls) {
  Weights1D raw;
  const double s = x / h - 0.5;  // position in cell-centre index units
  switch (kind) {
    case KernelKind::cell:
      raw.first = static_cast<int>(std::floor(x / h));
      raw.n = 1;
      raw.w[0] = 1.0;
      break;
    case KernelKind::trilinear: {
      const double f0 = std::floor(s);
      const double f = s - f0;
      raw.first = static_cast<int>(f0);
      raw.n = 2;
      raw.w[0] = 1.0 - f;
      raw.w[1] = f;
      break;
    }
    case KernelKind::trilinear_smoothed: {
      const double c = std::floor(s + 0.5);
      const double dlt = s - c;  // in [-1/2, 1/2)
      raw.first = static_cast<int>(c) - 1;
      raw.n = 3;
      raw.w[0] = 0.5 * (0.5 - dlt) * (0.5 - dlt);
      raw.w[1] = 0.75 - dlt * dlt;
      raw.w[2] = 0.5 * (0.5 + dlt) * (0.5 + dlt);
      break;
    }
  }
  if (!walls) return raw;
  // Mirror at the walls: index -1-m -> m, ncell+m -> ncell-1-m.
  auto fold = [ncell](int i) {
    if (i < 0) return -1 - i;
    if (i >= ncell) return 2 * ncell - 1 - i;
    return i;
  };
  int lo = ncell, hi = -1;
  for (int m = 0; m < raw.n; ++m) {
    const int i = fold(raw.first + m);
    lo = std::min(lo, i);
    hi = std::max(hi, i);
  }
  Weights1D out;
  out.first = lo;
  out.n = hi - lo + 1;
  for (int m = 0; m < raw.n; ++m) out.w[fold(raw.first + m) - lo] += raw.w[m];
  return out;
}

/// Face weights from cell weights: faces [first, first + n] (lower-face indexing: face f is the
/// lower face of cell f), w_face(f) = (w(f-1) + w(f)) / 2.
inline Weights1D face_weights(const Weights1D& c) {
  Weights1D f;
  f.first = c.first;
  f.n = c.n + 1;
  for (int m = 0; m < f.n; ++m) {
    const double lo = m >= 1 ? c.w[m - 1] : 0.0;
    const double hi = m < c.n ? c.w[m] : 0.0;
    f.w[m] = 0.5 * (lo + hi);
  }
  return f;
}

}  // namespace boycott::coupling
