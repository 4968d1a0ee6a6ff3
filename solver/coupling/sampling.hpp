#pragma once
// How fluid values are read at a particle centre (numerics.sampling):
//
//   "kernel"     the deposition kernel's weights (kernels.hpp), folded at the walls: the first
//                round's way. Exact for linear fields away from walls only.
//   "trilinear"  each field interpolated linearly in x, y and z between its own staggered nodes
//                (2 nodes per direction), with the wall rule of that field in the wall-bounded
//                direction y (channel width W, ny cells of size h):
//
//   field                          nodes in y       within half a cell (centres) or a cell (faces) of a wall
//   tangential velocity u, w       centres          linear to 0 on a no-slip wall; constant (mirror
//                                                   rule, du/dy = 0) under the slip top wall
//   wall-normal velocity v         faces 0 .. ny    plain: the wall rows hold v = 0
//   grad p, div tau, Du/Dt (x, z)  centres          linear extrapolation from the two nearest nodes
//   grad p, div tau, Du/Dt (y)     faces 1 .. ny-1  linear extrapolation (the wall rows are no values)
//   vorticity                      centres          linear extrapolation (one-sided at the wall)
//   solid fraction (alpha_f)       centres          the nearest cell's value (no extrapolation:
//                                                   a fraction stays in [0, 1])
//
// so a field that is linear between its nodes and meets its wall rule is read exactly, and a
// smooth one within h^2 |f''| / 8 (the interval next to a no-slip wall is h/2 long). Weights are
// Weights1D with n <= 2; those of the zero-at-wall rule need not sum to 1 (the wall value 0 takes
// the rest).
#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "coupling/kernels.hpp"

namespace boycott::coupling {

enum class Sampling { kernel, trilinear };

inline Sampling sampling_from_name(const std::string& s) {
  if (s == "kernel") return Sampling::kernel;
  if (s == "trilinear") return Sampling::trilinear;
  throw InputError(fmt::format("numerics.sampling = \"{}\": not a sampling of the coupling", s));
}

/// What a field does in the half cell (cell-centred nodes) or cell (face nodes) next to a wall.
enum class WallRule {
  zero,         ///< the value is 0 on the wall (no-slip tangential velocity)
  constant,     ///< the nearest node's value (mirror rule of a slip wall; alpha_f)
  extrapolate,  ///< linear from the two nearest interior nodes
  plain,        ///< face nodes whose wall rows hold the wall value (v = 0): ordinary interpolation
};

/// Linear weights at coordinate x (m, from the domain's lower edge) between nodes at
/// (j + offset) h, offset 0.5 (cell centres) or 0 (faces). Periodic direction: any j, the caller
/// wraps. Wall-bounded (ncell cells): cell-centred nodes j = 0 .. ncell-1, face nodes j = 0 ..
/// ncell, with rule `lo` at x = 0 and `hi` at x = ncell h. Needs ncell >= 2.
inline Weights1D linear_weights(double x, double h, bool centred, int ncell, bool walls, WallRule lo,
                                WallRule hi) {
  Weights1D w;
  const double s = x / h - (centred ? 0.5 : 0.0);  // position in node-index units
  auto pair = [&](int j0) {
    w.first = j0;
    w.n = 2;
    const double f = s - j0;  // outside [0, 1]: extrapolation
    w.w[0] = 1.0 - f;
    w.w[1] = f;
  };
  auto single = [&](int j, double weight) {
    w.first = j;
    w.n = 1;
    w.w[0] = weight;
  };
  if (!walls) {
    pair(static_cast<int>(std::floor(s)));
    return w;
  }
  if (centred) {
    const int last = ncell - 1;
    if (s < 0.0) {
      switch (lo) {
        case WallRule::zero:
          single(0, 2.0 * s + 1.0);
          break;  // 0 at s = -1/2, 1 at s = 0
        case WallRule::extrapolate:
          pair(0);
          break;
        default:
          single(0, 1.0);
          break;
      }
    } else if (s > last) {
      switch (hi) {
        case WallRule::zero:
          single(last, 2.0 * (last + 0.5 - s));
          break;
        case WallRule::extrapolate:
          pair(last - 1);
          break;
        default:
          single(last, 1.0);
          break;
      }
    } else {
      pair(std::min(static_cast<int>(std::floor(s)), last - 1));
    }
    return w;
  }
  // Face nodes: 0 and ncell are the walls.
  if (lo == WallRule::extrapolate || hi == WallRule::extrapolate) {
    // Interior rows 1 .. ncell-1 only.
    if (ncell < 3) {
      single(1, 1.0);
      return w;
    }
    pair(std::clamp(static_cast<int>(std::floor(s)), 1, ncell - 2));
    return w;
  }
  pair(std::clamp(static_cast<int>(std::floor(s)), 0, ncell - 1));
  return w;
}

}  // namespace boycott::coupling
