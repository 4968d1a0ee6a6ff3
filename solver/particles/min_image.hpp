#pragma once
// The minimum-image rule of the particle code (the only one): the difference of two coordinates
// in a periodic direction is taken to its nearest image.
#include <cmath>

namespace boycott::particles {

/// Minimum image of a coordinate difference d (m) in a direction of period L (m), with
/// inv_L = 1/L; L = 0 marks a direction that is not periodic (d is returned unchanged, and
/// inv_L may be any finite value). d - L round(d/L) rather than compare-and-shift: it has no
/// data-dependent branch, so the pair loops vectorise (round is one instruction, roundsd, on
/// every x86-64 machine with SSE4.1, which -march=native selects), and it holds for any |d|,
/// not only for |d| < 1.5 L.
inline double min_image(double d, double L, double inv_L) {
  return d - L * std::nearbyint(d * inv_L);
}

}  // namespace boycott::particles
