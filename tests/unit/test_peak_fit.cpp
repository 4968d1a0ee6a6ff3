// The peak of a curve and the refinement that finds it (stats/peak_fit.hpp, stats/peak_refine.hpp)
// on synthetic curves of known shape and noise, one family at a time (peak_curves.hpp).
// Quick tests use a few hundred curves per family; the coverage figures (docs/validation.md) come
// from test_peak_coverage.cpp (label long), 10 000 curves per family (binomial standard error 0.005).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "peak_curves.hpp"

using namespace boycott::stats;
using namespace peak_curves;

namespace {

/// What every resolvable family must show: the peak found within the resolution with fewer
/// points than a uniform grid of that resolution, and intervals near 68 % (a few hundred curves:
/// +-0.03 binomial; the tight figures are PeakCoverage's, test_peak_coverage.cpp).
void expect_found_cheaply(const Family& fam, double min_within) {
  const Summary s = summarise(refine_curves(fam, 300, 62));
  print(fam.name, s);
  EXPECT_GE(s.within, min_within) << fam.name;
  EXPECT_LT(s.most_points, kUniformGridPoints / 2) << fam.name;
  EXPECT_GE(s.cover_x, 0.62) << fam.name;
  EXPECT_GE(s.cover_y, 0.62) << fam.name;
  EXPECT_LE(s.cover_y, 0.82) << fam.name;
}

}  // namespace

TEST(PeakFit, ParabolaThroughThreeExactPointsHasItsVertexAndValue) {
  std::vector<PeakPoint> pts;
  for (double x : {15.0, 30.0, 45.0, 60.0, 75.0, 90.0})
    pts.push_back({x, 2.0 - 1e-3 * (x - 63.0) * (x - 63.0), 1e-6});
  const PeakEstimate e = estimate_peak(pts);
  EXPECT_NEAR(e.x, 63.0, 1e-6);
  EXPECT_NEAR(e.y, 2.0, 1e-9);
  EXPECT_FALSE(e.at_edge);
  EXPECT_EQ(e.points, 3);
  // Exact points of a parabola: the Gaussian through them peaks elsewhere, which is all the
  // interval holds (the model's error), and it holds the vertex.
  EXPECT_LE(e.x_low, 63.0);
  EXPECT_GE(e.x_high, 63.0);
  EXPECT_LT(e.x_error(), 2.0);
}

// Two points bracket no peak: the higher one is shown, its abscissa with no interval (NaN: a
// zero-width one would read as known exactly), its value with the draws' interval.
TEST(PeakFit, TwoPointsGiveTheHigherOneAndNoIntervalForItsPosition) {
  const PeakEstimate e = estimate_peak({{60, 1.8, 0.05}, {90, 1.2, 0.05}});
  ASSERT_TRUE(e.valid);
  EXPECT_FALSE(e.bracketed());
  EXPECT_EQ(e.x, 60.0);
  EXPECT_TRUE(std::isnan(e.x_low) && std::isnan(e.x_high));
  EXPECT_TRUE(e.at_edge);
  EXPECT_GT(e.y_error(), 0.0);
  const RefineStep s = next_refinement({{60, 1.8, 0.05}, {90, 1.2, 0.05}}, 0, {2.5, 4});
  EXPECT_EQ(s.stop, RefineStop::kTooFewPoints);
  EXPECT_EQ(s.why, "2 points: a peak needs 3 to be bracketed");
}

// One point is shown as it is: its value's interval is its own error exactly (as the curve gives
// it), not a draws' estimate of it, and its position has none.
TEST(PeakFit, OnePointIsShownWithItsOwnErrorAndNoIntervalForItsPosition) {
  const PeakEstimate e = estimate_peak({{65, -0.18635, 0.00969}});
  ASSERT_TRUE(e.valid);
  EXPECT_FALSE(e.bracketed());
  EXPECT_EQ(e.x, 65.0);
  EXPECT_EQ(e.y, -0.18635);
  EXPECT_DOUBLE_EQ(e.y_low, -0.18635 - 0.00969);
  EXPECT_DOUBLE_EQ(e.y_high, -0.18635 + 0.00969);
  EXPECT_TRUE(std::isnan(e.x_low) && std::isnan(e.x_high));
}

// Three points of a Gaussian peak (sigma 15 deg, maximum 1 at 70 deg) known almost exactly: the
// parabola through them misses the maximum's value by far more than the points' errors, and
// only the model's error (here the Gaussian through the three, which no fourth point is needed
// for) can say so. Without it the value's interval was the points' 1e-6.
TEST(PeakFit, ThreePointsAloneStillCarryTheShapesPartOfTheValuesError) {
  std::vector<PeakPoint> pts;
  for (double x : {60.0, 75.0, 90.0})
    pts.push_back({x, std::exp(-0.5 * (x - 70.0) * (x - 70.0) / 225.0), 1e-6});
  const PeakEstimate e = estimate_peak(pts);
  ASSERT_TRUE(e.bracketed());
  const double miss = std::abs(e.y - 1.0);
  EXPECT_GT(miss, 1e-3);  // the parabola's own error on this shape
  // Half the distance to the (here exact) Gaussian: the interval reaches half-way to the truth.
  EXPECT_NEAR(e.y_error(), 0.5 * miss, 0.05 * miss);
  EXPECT_LE(e.y_low, 1.0);
  EXPECT_GE(e.y_high, e.y);
}

// Three points 10-15 deg apart whose parabola's vertex interval is narrow (exact points): the
// interval holds the points' noise and nothing of the shape, so the refinement adds a point there
// instead of calling it resolved; with a fourth point near the vertex it can stop.
TEST(PeakRefine, ThreePointsAreNeverResolvedOnTheirParabolaAlone) {
  std::vector<PeakPoint> pts = {{65, 102.9, 0.2}, {75, 104.9, 0.2}, {90, 26.4, 0.1}};
  const RefineStep s = next_refinement(pts, 0, {5.0, 2});
  EXPECT_FALSE(s.peak.shape_checked);
  EXPECT_LT(s.peak.x_error(), 5.0);  // narrow: it would pass the resolution
  ASSERT_EQ(s.stop, RefineStop::kContinue) << s.why;
  EXPECT_GT(s.next_x, 65.0);
  EXPECT_LT(s.next_x, 75.0);
  pts.push_back({s.next_x, 109.0, 0.2});
  const RefineStep t = next_refinement(pts, 1, {5.0, 2});
  EXPECT_TRUE(t.peak.shape_checked);
  EXPECT_NE(t.stop, RefineStop::kTooFewPoints);
}

TEST(PeakFit, SamePointsInAnyOrderGiveTheSameEstimate) {
  std::vector<PeakPoint> pts = {{15, 1.1, 0.03}, {30, 1.4, 0.03}, {45, 1.9, 0.04},   {60, 2.2, 0.05},
                                {75, 2.1, 0.05}, {90, 1.0, 0.02}, {67.5, 2.25, 0.05}};
  const PeakEstimate a = estimate_peak(pts);
  std::reverse(pts.begin(), pts.end());
  std::swap(pts[1], pts[4]);
  const PeakEstimate b = estimate_peak(pts);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.x_low, b.x_low);
  EXPECT_EQ(a.x_high, b.x_high);
  EXPECT_EQ(a.y_low, b.y_low);
  const RefineStep sa = next_refinement(pts, 1, {2.5, 4}), sb = next_refinement(pts, 1, {2.5, 4});
  EXPECT_EQ(sa.next_x, sb.next_x);
  EXPECT_EQ(sa.why, sb.why);
}

TEST(PeakFit, MaximumAtTheFirstPointIsAtTheEdge) {
  const PeakEstimate e = estimate_peak({{15, 2.0, 0.01}, {30, 1.8, 0.01}, {45, 1.5, 0.01}, {60, 1.2, 0.01}});
  EXPECT_TRUE(e.at_edge);
  EXPECT_EQ(e.x, 15.0);
  EXPECT_GE(e.x_low, 15.0);
}

TEST(PeakRefine, SymmetricPeakFoundWithinTheResolutionWithFewerPointsThanAUniformGrid) {
  expect_found_cheaply(symmetric(), 0.93);
}

TEST(PeakRefine, SkewedPeakFoundWithinTheResolutionWithFewerPointsThanAUniformGrid) {
  expect_found_cheaply(skewed(), 0.85);
}

TEST(PeakRefine, PeakAtTheRangesEdgeIsFoundThereAndSaidToBeAtTheEdge) {
  const Summary s = summarise(refine_curves(edge(), 300, 62));
  print("edge", s);
  EXPECT_GE(s.within, 0.97);
  EXPECT_GE(s.stops.at(RefineStop::kAtRangeEdge), 270);
  EXPECT_LT(s.most_points, kUniformGridPoints / 2);
  EXPECT_GE(s.cover_x, 0.66);  // the truth sits on the boundary: one-sided intervals hold it often
  EXPECT_GE(s.cover_y, 0.62);
}

TEST(PeakRefine, UnresolvableFlatTopStopsEarlyAndSaysSo) {
  const auto trials = refine_curves(flat_top(), 300, 62);
  const Summary s = summarise(trials);
  print("flat top", s);
  // Measured 0.81 of 2000 curves stop as indistinct; the rest claim a peak their plateau does not
  // have (the points a parabola fits bend down by chance): docs/validation.md.
  EXPECT_GE(s.stops.at(RefineStop::kIndistinct), 0.72 * 300);
  EXPECT_LE(s.stops.count(RefineStop::kMaxPoints) ? s.stops.at(RefineStop::kMaxPoints) : 0, 3);
  for (const auto& t : trials)
    if (t.stop == RefineStop::kIndistinct) {
      EXPECT_NE(t.why.find("cannot be told apart within their errors"), std::string::npos) << t.why;
      EXPECT_LT(t.added, kMaxPoints);
    }
}

TEST(PeakRefine, AddsNoMoreThanMaxPoints) {
  const Family fam = skewed();
  std::vector<PeakPoint> pts;
  for (double x = kLo; x <= kHi; x += kStep) pts.push_back({x, fam.f(x, 66.0), 0.2});  // errors too large
  int added = 0;
  for (;; ++added) {
    const RefineStep s = next_refinement(pts, added, {0.1, 2});
    if (s.stop != RefineStop::kContinue) break;
    pts.push_back({s.next_x, fam.f(s.next_x, 66.0), 0.2});
  }
  EXPECT_LE(added, 2);
}
