#pragma once
// Where to sample a curve next to find its maximum (study key [refine]), and when to stop: the
// rule behind `study run`'s refinement rounds, one added point per curve and round.
//
// From the points so far (peak_fit.hpp estimates the peak and its 68 % interval):
// 1. stop when the curve has more than the parabola's three points (through three it is exact,
//    and its interval holds the points' noise, not its shape: PeakEstimate::shape_checked), the
//    position's half-width is at most the resolution, the nearest points on either
//    side of the estimate lie within 2 resolutions of it (the quadratic's error on a skewed peak
//    shrinks with that spacing) and the points within 4 resolutions bend down (their curvature
//    below zero by twice its error: a peak, not a plateau within the errors): resolved; at the
//    range's edge when the estimate sits on the first or last sampled abscissa (the maximum of
//    the range: the curve may rise beyond it);
// 2. stop when max_points have been added;
// 3. stop when the highest point's neighbours lie within its errors and the points do not bend
//    down (they cannot be told apart: a point between them would be as uncertain; more precise
//    points, replicas or longer runs, are what helps);
// 4. otherwise add a point inside the bracket around the highest point (its neighbours): where the
//    fit puts the vertex, when that lies in the bracket at least half the resolution and a quarter
//    of its gap away from every point; else the middle of the wider side of the bracket;
// 5. stop as in 3 when that side is already narrower than the resolution.
// The rule is a function of the points alone (the estimate's draws are seeded), so a resumed
// study chooses the points it chose before, whatever order its cases finished in.
#include <string>
#include <vector>

#include "stats/peak_fit.hpp"

namespace boycott::stats {

struct RefineRule {
  double resolution = 1.0;  ///< stop when the peak's position is known to this (68 % half-width)
  int max_points = 4;       ///< points added at most
};

enum class RefineStop {
  kContinue,      ///< a point is to be added at RefineStep::next_x
  kResolved,      ///< the position is known to the resolution, inside the range
  kAtRangeEdge,   ///< known to the resolution, at the first or last sampled abscissa
  kMaxPoints,     ///< max_points added
  kIndistinct,    ///< the points around the highest cannot be told apart within their errors
  kTooFewPoints,  ///< fewer than 3 points: no bracket
};
/// resolved, at_range_edge, max_points, indistinct, too_few_points, continue.
const char* to_string(RefineStop s);
/// Why a curve of `points` (< kBracketPoints) points has no peak estimate: one sentence.
std::string too_few_points_why(std::size_t points);

struct RefineStep {
  RefineStop stop = RefineStop::kContinue;
  double next_x = 0.0;  ///< with kContinue
  /// Why, in a sentence of numbers: the point's reason (recorded with it) or the stop's.
  std::string why;
  PeakEstimate peak;  ///< the estimate the step rests on
};

/// The next step of the refinement of the curve through `points` (any order), `added` points
/// having been added to it so far.
RefineStep next_refinement(const std::vector<PeakPoint>& points, int added, const RefineRule& rule,
                           const PeakFitOptions& options = {});

}  // namespace boycott::stats
