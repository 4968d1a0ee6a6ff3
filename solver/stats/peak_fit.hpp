#pragma once
// Where a sampled curve has its maximum, and how well that is known: the peak of a settling curve
// (|<<w_p>>| or r_acc against the angle) from its points and their covering errors.
//
// The estimator: the parabola through the highest point and its two neighbours (its vertex kept
// between them; a weighted least-squares quadratic, exact through three points). Three points and
// not five: on a skewed peak the vertex of a wider quadratic moves with the far points (a bias of
// 1-2 deg at 5 deg spacing in the coverage tests), and the refinement puts points near the peak.
// Its uncertainty, the 68 % interval of position and value:
// - Monte Carlo over the points' errors: each point drawn from a normal with its error as standard
//   deviation, the highest point and its neighbours found again in every draw (which point is
//   highest is uncertain too), the 15.9 and 84.1 percentiles of the draws' vertices; the value's
//   interval moved down by the draws' mean bias (the highest of noisy values exceeds the true
//   maximum, and draws of noisy values plus noise more so);
// - the model's error, added in quadrature on each side: the part of the disagreement between
//   the parabola's vertex and those of the weighted quadratic through five points (where there
//   are more than three) and of a Gaussian (a parabola through the logarithms) through the three
//   that the points' noise does not explain (half the distance, less its scatter over draws of
//   the points, in quadrature). Three points alone give the Gaussian only: it checks how the
//   value between them depends on the shape, little of where the vertex lies.
// Coverage over noisy synthetic curves, one family at a time, after the refinement
// (tests/unit/test_peak_coverage.cpp, docs/validation.md "Peaks"): position / value 0.708 / 0.716
// on symmetric peaks, 0.682 / 0.680 on skewed ones (the half-distance alone, with the noise in it
// counted twice: 0.737 / 0.738 and 0.697 / 0.706). Why not a Gaussian process or a spline: with
// 5-15 points per curve they need a length scale the data cannot fix, and their intervals depend
// on it; the parabola's assumption is local and the coverage tests check it.
// The draws come from a generator of our own (SplitMix64 and Box-Muller), so the same points give
// the same estimate on every machine: the refinement's choices rest on it (peak_refine.hpp).
#include <cstdint>
#include <vector>

namespace boycott::stats {

/// A point of a curve: abscissa, value and the value's covering error (half-width ~68 %, > 0).
struct PeakPoint {
  double x = 0.0;
  double y = 0.0;
  double error = 0.0;
};

struct PeakFitOptions {
  int draws = 1000;           ///< Monte Carlo draws over the points' errors
  std::uint64_t seed = 2021;  ///< of the draws: fixed, so an estimate is a function of its points
};

/// Points that bracket a peak: the highest and a neighbour on each side.
inline constexpr int kBracketPoints = 3;

/// The maximum of a curve and its 68 % intervals.
struct PeakEstimate {
  bool valid = false;  ///< false with no point
  double x = 0.0;      ///< where the maximum is
  double x_low = 0.0, x_high = 0.0;
  double y = 0.0;  ///< its value
  double y_low = 0.0, y_high = 0.0;
  int points = 0;          ///< points of the parabola (the highest and its neighbours)
  std::size_t top = 0;     ///< index (in x order) of the highest measured point
  bool at_edge = false;    ///< the estimate lies at the first or last sampled abscissa
  double model_error = 0;  ///< the quadratic's own part of the position's uncertainty (above)
  /// Fewer than kBracketPoints points bracket no peak: x is the highest measured abscissa and its
  /// interval is NaN (unknown, where a zero-width one would read as known exactly).
  bool bracketed() const { return points >= kBracketPoints; }
  /// More points than the parabola's three: the five-point quadratic checks where its vertex lies.
  /// Through exactly three the parabola is exact, and its position interval is the points' noise
  /// alone, however wrong the shape: such an estimate is never called resolved.
  bool shape_checked = false;
  double x_error() const { return 0.5 * (x_high - x_low); }
  double y_error() const { return 0.5 * (y_high - y_low); }
};

/// The maximum of the curve through `points` (any order; abscissae distinct).
PeakEstimate estimate_peak(std::vector<PeakPoint> points, const PeakFitOptions& options = {});

/// The curvature d2y/dx2 of the weighted quadratic through the points within `reach` of x, and its
/// standard error (the errors taken as standard deviations).
struct Curvature {
  double value = 0.0, error = 0.0;
  int points = 0;
  /// Below zero by more than twice its error: the points there bend down, a peak and not a
  /// plateau their errors hide.
  bool peaked() const { return points >= 3 && value + 2.0 * error < 0.0; }
};
Curvature curvature_near(std::vector<PeakPoint> points, double x, double reach);

/// The points sorted by abscissa.
std::vector<PeakPoint> sorted_by_x(std::vector<PeakPoint> points);

/// Whether two values cannot be told apart within their covering errors: |a - b| below the
/// covering error of their difference, sqrt(ea^2 + eb^2).
bool indistinct(const PeakPoint& a, const PeakPoint& b);

}  // namespace boycott::stats
