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

/// The running bounding box of displacements D_i = p_i - ref_i (m), kept in eight lanes that are
/// merged by result(): GCC does not vectorise a floating-point min/max reduction by itself (it
/// would need -ffast-math) but does the lanes' loop. Min and max do not round, so the box is the
/// one pass's in any order (a -0 against a +0 aside, which neither the box's extent nor its
/// centre sees). Particles may be added in ranges (the fused kick adds each block it drifts).
class DisplacementBox {
 public:
  static constexpr std::size_t kLanes = 8;
  DisplacementBox() {
    for (std::size_t l = 0; l < kLanes; ++l)
      lx_[l] = ly_[l] = lz_[l] = std::numeric_limits<double>::infinity(),
      hx_[l] = hy_[l] = hz_[l] = -std::numeric_limits<double>::infinity();
  }
  /// Adds particles [b, e).
  void add(std::size_t b, std::size_t e, const double* __restrict x, const double* __restrict y,
           const double* __restrict z, const double* __restrict rx, const double* __restrict ry,
           const double* __restrict rz) {
    // The lanes as locals while the loop runs (through `this` they would be stored back each
    // iteration).
    double lx[kLanes], ly[kLanes], lz[kLanes], hx[kLanes], hy[kLanes], hz[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l)
      lx[l] = lx_[l], ly[l] = ly_[l], lz[l] = lz_[l], hx[l] = hx_[l], hy[l] = hy_[l], hz[l] = hz_[l];
    auto lane = [&](std::size_t l, double dx, double dy, double dz) {
      lx[l] = dx < lx[l] ? dx : lx[l];
      ly[l] = dy < ly[l] ? dy : ly[l];
      lz[l] = dz < lz[l] ? dz : lz[l];
      hx[l] = dx > hx[l] ? dx : hx[l];
      hy[l] = dy > hy[l] ? dy : hy[l];
      hz[l] = dz > hz[l] ? dz : hz[l];
    };
    std::size_t i = b;
    for (; i + kLanes <= e; i += kLanes)
      for (std::size_t l = 0; l < kLanes; ++l)
        lane(l, x[i + l] - rx[i + l], y[i + l] - ry[i + l], z[i + l] - rz[i + l]);
    for (std::size_t l = 0; i < e; ++i, ++l) lane(l, x[i] - rx[i], y[i] - ry[i], z[i] - rz[i]);
    for (std::size_t l = 0; l < kLanes; ++l)
      lx_[l] = lx[l], ly_[l] = ly[l], lz_[l] = lz[l], hx_[l] = hx[l], hy_[l] = hy[l], hz_[l] = hz[l];
  }
  /// lo and hi (sum left at zero).
  DisplacementSpread result() const {
    DisplacementSpread s;
    for (std::size_t l = 0; l < kLanes; ++l) {
      s.lo[0] = lx_[l] < s.lo[0] ? lx_[l] : s.lo[0];
      s.lo[1] = ly_[l] < s.lo[1] ? ly_[l] : s.lo[1];
      s.lo[2] = lz_[l] < s.lo[2] ? lz_[l] : s.lo[2];
      s.hi[0] = hx_[l] > s.hi[0] ? hx_[l] : s.hi[0];
      s.hi[1] = hy_[l] > s.hi[1] ? hy_[l] : s.hi[1];
      s.hi[2] = hz_[l] > s.hi[2] ? hz_[l] : s.hi[2];
    }
    return s;
  }

 private:
  double lx_[kLanes], ly_[kLanes], lz_[kLanes], hx_[kLanes], hy_[kLanes], hz_[kLanes];
};

/// The bounding box of D_i = p_i - ref_i over particles [0, n) (lo, hi; sum left at zero). The
/// box alone usually settles the test (box_within_half_skin); the ordered sums, and on several
/// ranks their collective, are needed only where it does not.
inline DisplacementSpread displacement_box(std::size_t n, const double* __restrict x,
                                           const double* __restrict y, const double* __restrict z,
                                           const double* __restrict rx, const double* __restrict ry,
                                           const double* __restrict rz) {
  DisplacementBox b;
  b.add(0, n, x, y, z, rx, ry, rz);
  return b.result();
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
