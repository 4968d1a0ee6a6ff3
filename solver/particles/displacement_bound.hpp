#pragma once
// When the Verlet list must be rebuilt. A pair missing from the list was at least 2 r_max + skin
// apart at the build, so it can touch only after its distance has shrunk by more than the skin.
// The distance changes by at most |D_i - D_j| <= |D_i - c| + |D_j - c| for any vector c common
// to all particles (D the displacements since the build), so the list stays exact while
// max_i |D_i - c| <= skin / 2 for some c. The best c is the centre of the smallest ball around
// the displacements; two cheap candidates are tested: the mean (a uniform drift of the whole
// packing costs nothing) and the centre of the displacements' bounding box (a sliding layer over
// a bed at rest: half the spread instead of most of it).
#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>

namespace boycott::particles {

/// Per component: the sum, the smallest and the largest displacement (m).
struct DisplacementSpread {
  std::array<double, 3> sum{0.0, 0.0, 0.0};
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};
};

/// The bounding box of D_i = p_i - ref_i over particles [0, n) (lo, hi; sum left at zero). The
/// box alone usually settles the test (box_within_half_skin); the ordered sums, and on several
/// ranks their collective, are needed only where it does not.
inline DisplacementSpread displacement_box(std::size_t n, const double* __restrict x,
                                           const double* __restrict y, const double* __restrict z,
                                           const double* __restrict rx, const double* __restrict ry,
                                           const double* __restrict rz) {
  DisplacementSpread s;
  double lx = s.lo[0], ly = s.lo[1], lz = s.lo[2], hx = s.hi[0], hy = s.hi[1], hz = s.hi[2];
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - rx[i], dy = y[i] - ry[i], dz = z[i] - rz[i];
    lx = dx < lx ? dx : lx;
    ly = dy < ly ? dy : ly;
    lz = dz < lz ? dz : lz;
    hx = dx > hx ? dx : hx;
    hy = dy > hy ? dy : hy;
    hz = dz > hz ? dz : hz;
  }
  s.lo = {lx, ly, lz}, s.hi = {hx, hy, hz};
  return s;
}

/// The sums of D_i over particles [0, n) (m), each added in particle order (the mean centre's
/// bits do not depend on the vector width). The three components in one pass: their chains of
/// dependent additions overlap.
inline std::array<double, 3> displacement_sums(std::size_t n, const double* __restrict x,
                                               const double* __restrict y, const double* __restrict z,
                                               const double* __restrict rx, const double* __restrict ry,
                                               const double* __restrict rz) {
  double sx = 0.0, sy = 0.0, sz = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sx += x[i] - rx[i];
    sy += y[i] - ry[i];
    sz += z[i] - rz[i];
  }
  return {sx, sy, sz};
}

/// max_i |D_i - c|^2 (m^2) over particles [0, n) for two centres c (m): {about ca, about cb}.
inline std::array<double, 2> largest_offsets2(std::size_t n, const double* __restrict x,
                                              const double* __restrict y, const double* __restrict z,
                                              const double* __restrict rx, const double* __restrict ry,
                                              const double* __restrict rz, const std::array<double, 3>& ca,
                                              const std::array<double, 3>& cb) {
  double wa = 0.0, wb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - rx[i], dy = y[i] - ry[i], dz = z[i] - rz[i];
    const double ax = dx - ca[0], ay = dy - ca[1], az = dz - ca[2];
    const double bx = dx - cb[0], by = dy - cb[1], bz = dz - cb[2];
    const double a2 = ax * ax + ay * ay + az * az, b2 = bx * bx + by * by + bz * bz;
    wa = a2 > wa ? a2 : wa;
    wb = b2 > wb ? b2 : wb;
  }
  return {wa, wb};
}

/// The two centres tested: the mean displacement of `count` particles and the bounding box's
/// centre (m).
inline std::array<std::array<double, 3>, 2> displacement_centres(const DisplacementSpread& s, double count) {
  std::array<std::array<double, 3>, 2> c{};
  for (int k = 0; k < 3; ++k) {
    c[0][k] = count > 0.0 ? s.sum[k] / count : 0.0;
    c[1][k] = s.lo[k] <= s.hi[k] ? 0.5 * (s.lo[k] + s.hi[k]) : 0.0;
  }
  return c;
}

/// True when the bounding box alone proves that every particle is within skin/2 of its centre
/// (half its diagonal is below skin/2), so that the pass over the particles can be skipped: the
/// usual case in the steps well before a rebuild. The margin keeps the answer that of the exact
/// test where the two differ only by round-off.
inline bool box_within_half_skin(const DisplacementSpread& s, double skin_m) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) d2 += (s.hi[k] - s.lo[k]) * (s.hi[k] - s.lo[k]);
  return d2 <= skin_m * skin_m * (1.0 - 1e-12);
}

}  // namespace boycott::particles
