#include "stats/peak_refine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace boycott::stats {
namespace {

/// The points nearest the estimate on each side lie within this many resolutions of it before it
/// counts as resolved: the quadratic's error (a skewed peak's vertex moves with the spacing)
/// shrinks with that spacing.
constexpr double kCloseResolutions = 2.0;
/// A peak is told from a plateau by the curvature of the points within this many resolutions of
/// the estimate (stats::Curvature::peaked).
constexpr double kCurvatureReachResolutions = 4.0;

/// The distance from x to the nearest point.
double distance_to_points(const std::vector<PeakPoint>& p, double x) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& q : p) d = std::min(d, std::abs(q.x - x));
  return d;
}

std::string peak_text(const PeakEstimate& e) {
  return fmt::format("peak at {:.4g} in [{:.4g}, {:.4g}] (+-{:.3g})", e.x, e.x_low, e.x_high, e.x_error());
}

/// Whether the nearest points on either side of x lie within kCloseResolutions of it (at an end,
/// the one side).
bool sampled_closely(const std::vector<PeakPoint>& p, double x, double resolution) {
  double below = -std::numeric_limits<double>::infinity(), above = std::numeric_limits<double>::infinity();
  for (const auto& q : p) {
    if (q.x < x) below = std::max(below, q.x);
    if (q.x > x) above = std::min(above, q.x);
  }
  const double reach = kCloseResolutions * resolution;
  return (std::isinf(below) || x - below <= reach) && (std::isinf(above) || above - x <= reach);
}

/// Whether every neighbour of the highest point is within the errors of it.
bool neighbours_indistinct(const std::vector<PeakPoint>& p, std::size_t top) {
  bool all = true;
  if (top > 0) all = all && indistinct(p[top], p[top - 1]);
  if (top + 1 < p.size()) all = all && indistinct(p[top], p[top + 1]);
  return all;
}

RefineStep indistinct_stop(RefineStep s, const std::string& what) {
  s.stop = RefineStop::kIndistinct;
  s.why = fmt::format(
      "{} cannot be told apart within their errors; {}: a point between them would be as uncertain, more "
      "precise points (replicas, longer runs) would narrow it",
      what, peak_text(s.peak));
  return s;
}

/// Steps 4 and 5: the point to add inside the bracket around the highest point.
RefineStep bracket_point(const std::vector<PeakPoint>& p, RefineStep s, const RefineRule& rule) {
  const std::size_t top = s.peak.top;
  const double lo = top > 0 ? p[top - 1].x : p[top].x;
  const double hi = top + 1 < p.size() ? p[top + 1].x : p[top].x;
  const double v = s.peak.x;
  if (v > lo && v < hi) {
    const double gap = v < p[top].x ? p[top].x - lo : hi - p[top].x;
    if (distance_to_points(p, v) >= std::max(0.5 * rule.resolution, 0.25 * gap)) {
      s.next_x = v;
      s.why = fmt::format("the fit's vertex, {}, between {:.4g} and {:.4g}", peak_text(s.peak), lo, hi);
      return s;
    }
  }
  const bool go_left = p[top].x - lo > hi - p[top].x;
  const double a = go_left ? lo : p[top].x, b = go_left ? p[top].x : hi;
  if (b - a < rule.resolution)
    return indistinct_stop(
        s, fmt::format("the points around the highest ({:.4g}), closer than the resolution {:.3g},", p[top].x,
                       rule.resolution));
  s.next_x = 0.5 * (a + b);
  s.why = fmt::format("the middle of the wider side [{:.4g}, {:.4g}] of the highest point; {}", a, b,
                      peak_text(s.peak));
  return s;
}

}  // namespace

const char* to_string(RefineStop s) {
  switch (s) {
    case RefineStop::kContinue:
      return "continue";
    case RefineStop::kResolved:
      return "resolved";
    case RefineStop::kAtRangeEdge:
      return "at_range_edge";
    case RefineStop::kMaxPoints:
      return "max_points";
    case RefineStop::kIndistinct:
      return "indistinct";
    case RefineStop::kTooFewPoints:
      return "too_few_points";
  }
  return "?";
}

std::string too_few_points_why(std::size_t points) {
  return fmt::format("{} point{}: a peak needs {} to be bracketed", points, points == 1 ? "" : "s",
                     kBracketPoints);
}

RefineStep next_refinement(const std::vector<PeakPoint>& points, int added, const RefineRule& rule,
                           const PeakFitOptions& options) {
  RefineStep s;
  const std::vector<PeakPoint> p = sorted_by_x(points);
  if (p.size() < kBracketPoints) {
    s.stop = RefineStop::kTooFewPoints;
    s.why = too_few_points_why(p.size());
    return s;
  }
  s.peak = estimate_peak(p, options);
  const bool peaked = curvature_near(p, s.peak.x, kCurvatureReachResolutions * rule.resolution).peaked();
  if (s.peak.shape_checked && s.peak.x_error() <= rule.resolution &&
      sampled_closely(p, s.peak.x, rule.resolution)) {
    if (s.peak.at_edge) {
      s.stop = RefineStop::kAtRangeEdge;
      s.why = fmt::format("{}, at the edge of the sampled range: the curve may rise beyond it",
                          peak_text(s.peak));
      return s;
    }
    if (peaked) {
      s.stop = RefineStop::kResolved;
      s.why = fmt::format("{}, within the resolution {:.3g}", peak_text(s.peak), rule.resolution);
      return s;
    }
  }
  if (added >= rule.max_points) {
    s.stop = RefineStop::kMaxPoints;
    s.why = fmt::format("{} points added (max_points); {}", added, peak_text(s.peak));
    return s;
  }
  if (neighbours_indistinct(p, s.peak.top) && !peaked)
    return indistinct_stop(s, fmt::format("the highest point ({:.4g}: {:.4g} +- {:.2g}) and its neighbours",
                                          p[s.peak.top].x, p[s.peak.top].y, p[s.peak.top].error));
  return bracket_point(p, s, rule);
}

}  // namespace boycott::stats
