// Whether one run's error bar keeps its promise on series that are not AR(1) (issue 61): over
// 10 000 series per figure with fixed seeds, the share whose stated interval holds the true mean
// (0, or 1 for a relative target). Families (tests/unit/series_families.hpp): AR(1) of tau_int 10
// steps; sums of two AR(1) processes 3-30 times apart in time, the slow one carrying 0.1-0.5 of
// the variance; a damped oscillation (period 8-40 steps, envelope 1-4 periods) plus white noise.
// Windows are counted in the slowest time scale (the slow AR(1)'s tau_int, the envelope's decay
// time). Each figure is held within kBand of the value measured when the rule was settled (so a
// change of the rules worth 0.02 shows), and within 0.65-0.71 (the promise). Binomial standard
// error of a coverage near 0.68 at 10 000 series: 0.0047. Label `long` (minutes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "stats/autocorrelation.hpp"
#include "stats/distributions.hpp"
#include "stats/precision_target.hpp"
#include "stats/transient.hpp"
#include "stats/window_error.hpp"
#include "tests/unit/early_stop_coverage.hpp"
#include "tests/unit/series_families.hpp"

using namespace boycott::stats;
using boycott::testing::FamilySeries;

namespace {

constexpr int kSeries = 10000;
constexpr double kBand = 0.015;  // about 3 binomial standard errors

using Family = std::function<FamilySeries(double window, std::mt19937_64&)>;
Family family(const std::string& name) {
  if (name == "ar1")
    return [](double w, std::mt19937_64& r) { return boycott::testing::ar1_series(10.0, w, r); };
  if (name == "two_scales") return boycott::testing::two_scale_series;
  return boycott::testing::oscillation_series;
}

// One run's error as a run with a fixed window reports it (window_error), `narrow` times its
// half-width (1: as reported; below 1: a planted defect).
double one_run_coverage(const std::string& name, double window, std::uint64_t seed, double narrow = 1.0) {
  std::mt19937_64 rng(seed);
  const Family make = family(name);
  int covered = 0;
  for (int s = 0; s < kSeries; ++s) {
    const FamilySeries f = make(window, rng);
    const WindowError w = window_error(f.x, 0.0, static_cast<double>(f.x.size()));
    covered += std::abs(w.e.mean) <= narrow * w.err.covering_error;
  }
  const double c = static_cast<double>(covered) / kSeries;
  std::printf("coverage, one run, %s, %g slowest times: %.4f\n", name.c_str(), window, c);
  return c;
}

void expect_figure(double measured, double settled, const std::string& what) {
  EXPECT_NEAR(measured, settled, kBand) << what;
  EXPECT_GE(measured, 0.65) << what;
  EXPECT_LE(measured, 0.71) << what;
}

}  // namespace

TEST(FamilyCoverage, OneRunErrorCoversTwoThirdsFrom10SlowestTimesOnEveryFamily) {
  struct Figure {
    const char* family;
    double window, settled;
  };
  // Settled with batches of 40 counted correlation times (window_error.hpp); with 20 the two-scale
  // figures read 0.6713 / 0.6732 / 0.6578 / 0.6764 (the one at 50 slowest times 1.8 binomial
  // errors above the promise's floor, its neighbouring batches correlating through the slow part).
  const Figure figures[] = {{"ar1", 10, 0.6661},         {"ar1", 50, 0.6848},
                            {"ar1", 200, 0.6763},        {"two_scales", 10, 0.6739},
                            {"two_scales", 20, 0.6796},  {"two_scales", 50, 0.6719},
                            {"two_scales", 200, 0.6748}, {"oscillation", 10, 0.6906},
                            {"oscillation", 50, 0.6827}, {"oscillation", 200, 0.6864}};
  std::uint64_t seed = 61000;
  for (const auto& f : figures)
    expect_figure(one_run_coverage(f.family, f.window, ++seed), f.settled,
                  std::string(f.family) + " " + std::to_string(f.window));
}

TEST(FamilyCoverage, AnErrorFivePerCentTooNarrowFallsOutsideTheBand) {
  // The planted defect: the same figure with every half-width 5 % narrower, which moves a
  // coverage near 0.68 by up to 2 phi(1) 0.05 ~ 0.024 (less where few degrees of freedom flatten
  // the distribution at the bar's end); the band must not let it through.
  const double settled = 0.6763;  // ar1, 200 correlation times, seed as above
  const double defective = one_run_coverage("ar1", 200, 61003, 0.95);  // 0.6580
  EXPECT_GT(std::abs(defective - settled), kBand);
}

namespace {

// A run that time.target_rel_error stops (PrecisionTarget, two-stage), on 1 + a family's series,
// the target set to need ~`goal` slowest times, and run to at most 12 times that (its time.end).
// Every series counts: one the target stopped with the error it reports at the stop, one it did
// not with the error a run reports at its end (the fixed window's), as a user gets them. Leaving
// the unstopped out would select: they are the series whose first stage was noisiest.
struct TargetFigures {
  double coverage = 0.0;            // every series
  double stopped_coverage = 0.0;    // those the target stopped
  double unstopped_coverage = 0.0;  // those that ran to the end
  int stopped = 0;
};
TargetFigures target_coverage(const std::string& name, double goal, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Family make = family(name);
  int covered_stopped = 0, covered_unstopped = 0;
  TargetFigures t;
  for (int s = 0; s < kSeries; ++s) {
    const FamilySeries f = make(12.0 * goal, rng);
    const double rel = one_sigma_t_factor(7.0) * std::sqrt(2.0 * f.tau_int / (goal * f.slowest));
    PrecisionTarget target(rel);
    std::vector<double> w;
    w.reserve(f.x.size());
    bool done = false;
    for (double v : f.x) {
      w.push_back(1.0 + v);
      if ((done = target.reached(w, 0.0, static_cast<double>(w.size())))) break;
    }
    const WindowError e =
        window_error(w, 0.0, static_cast<double>(w.size()), done ? &target.plan() : nullptr);
    const bool covered = std::abs(e.e.mean - 1.0) <= e.err.covering_error;
    t.stopped += done;
    (done ? covered_stopped : covered_unstopped) += covered;
  }
  const int unstopped = kSeries - t.stopped;
  t.coverage = static_cast<double>(covered_stopped + covered_unstopped) / kSeries;
  t.stopped_coverage = static_cast<double>(covered_stopped) / std::max(t.stopped, 1);
  t.unstopped_coverage = static_cast<double>(covered_unstopped) / std::max(unstopped, 1);
  std::printf(
      "coverage, target stop, %s, goal %g slowest times: %.4f over every series; %.4f over the %d "
      "the target stopped, %.4f over the %d run to the end\n",
      name.c_str(), goal, t.coverage, t.stopped_coverage, t.stopped, t.unstopped_coverage, unstopped);
  return t;
}

}  // namespace

// time.target_rel_error on AR(1) series (tau_int 10 steps): the error a run reports where the target
// stopped it, at three target levels, 10 000 series each (test_run_statistics.cpp holds a quick
// check on 1 000).
TEST(EarlyStopCoverage, TheErrorAtTheStopCoversTwoThirdsOnAr1AtThreeTargets) {
  for (double target : {0.2, 0.15, 0.12}) {
    const auto f =
        boycott::testing::ar1_early_stop_coverage(target, kSeries, 5000 + static_cast<int>(target * 1000));
    std::printf("coverage, early stop at target %g: %.4f (stopped %d of %d, mean %.0f tau_int)\n", target,
                f.coverage(), f.stopped, kSeries, f.mean_tau);
    EXPECT_EQ(f.stopped, kSeries);
    EXPECT_GE(f.coverage(), 0.66) << "target " << target;
    EXPECT_LE(f.coverage(), 0.705) << "target " << target;
  }
}

// Settled on 10 000 series per family under the tau_int trigger, 4 batches at most at the first
// stage and batches of 40 counted correlation times (the test was disabled after 2 000 series gave
// 0.653 / 0.646 on two scales / oscillation at an earlier state of the rules). Every series
// counts: 1.9 / 2.8 / 6.7 % never stop within 12x the goal and report their end's fixed-window
// error, which covers 0.589 / 0.638 / 0.689 of them; over the stopped ones alone the figures are
// 0.6696 / 0.6535 / 0.6821. With batches of 20: 0.6757 / 0.6540 / 0.6835, 0.8 / 2.0 / 6.4 %
// unstopped (the first stage's conservative count now often makes 3 batches, not 4, so its plan
// scatters more). Two scales sits within 1 binomial error above the promise's 0.65.
TEST(FamilyCoverage, ARunTheTargetStopsCoversTwoThirdsOnEveryFamily) {
  struct Figure {
    const char* family;
    double goal, settled;
  };
  const Figure figures[] = {{"ar1", 300, 0.6681}, {"two_scales", 300, 0.6531}, {"oscillation", 300, 0.6826}};
  std::uint64_t seed = 62000;
  for (const auto& f : figures)
    expect_figure(target_coverage(f.family, f.goal, ++seed).coverage, f.settled, f.family);
}

namespace {

struct AutoFigures {
  double coverage = 0.0, cut = 0.0, unbiased = 0.0;
};
// average_from = "auto" (cut_at_transient) on a family's series of `window` slowest times plus a
// start-up decay A exp(-t / (5 slowest)) that biases the whole series' mean by `bias_se` true
// standard errors: the reported error's coverage, the share of series cut, and the share whose
// remaining bias is below half a standard error of what is kept.
AutoFigures auto_window_figures(const std::string& name, double window, double bias_se, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Family make = family(name);
  AutoFigures a;
  for (int s = 0; s < kSeries; ++s) {
    FamilySeries f = make(window, rng);
    const double n = static_cast<double>(f.x.size()), decay = 5.0 * f.slowest;
    const double amplitude = bias_se * f.true_se() * n / decay;
    auto transient = [&](std::size_t i) { return amplitude * std::exp(-static_cast<double>(i) / decay); };
    for (std::size_t i = 0; i < f.x.size(); ++i) f.x[i] += transient(i);
    const ChosenWindow c = cut_at_transient(StepSeries{}, f.x, 0.0, n);
    const std::size_t k = f.x.size() - c.window.size();
    double residual = 0.0;
    for (std::size_t i = k; i < f.x.size(); ++i)
      residual += transient(i) / static_cast<double>(c.window.size());
    const WindowError w = window_error(c.window, 0.0, n);
    a.coverage += (std::abs(w.e.mean) <= w.err.covering_error) / static_cast<double>(kSeries);
    a.cut += (k > 0) / static_cast<double>(kSeries);
    a.unbiased += (residual < 0.5 * std::sqrt(2.0 * f.tau_int / static_cast<double>(c.window.size()))) /
                  static_cast<double>(kSeries);
  }
  std::printf(
      "auto window, %s, %g slowest times, transient of %g standard errors: coverage %.4f, cut %.4f, "
      "unbiased after the cut %.4f\n",
      name.c_str(), window, bias_se, a.coverage, a.cut, a.unbiased);
  return a;
}

}  // namespace

TEST(FamilyCoverage, AnAutomaticWindowCutsFewStationarySeriesAndItsErrorCovers) {
  struct Figure {
    const char* family;
    double settled;
  };
  const Figure figures[] = {{"ar1", 0.6815}, {"two_scales", 0.6635}, {"oscillation", 0.6873}};
  std::uint64_t seed = 63000;
  for (const auto& f : figures) {
    const AutoFigures a = auto_window_figures(f.family, 50.0, 0.0, ++seed);
    expect_figure(a.coverage, f.settled, f.family);
    EXPECT_LE(a.cut, 0.1) << f.family;
  }
}

TEST(FamilyCoverage, AnAutomaticWindowCutsAStrongTransientToBelowHalfAStandardErrorOnEveryFamily) {
  struct Figure {
    const char* family;
    double coverage, unbiased;
  };
  // Settled with the fitted decay's guard, which also detects a decay that no single segment shows
  // (transient.hpp). Before the guard the two-scale and oscillating families were cut too early:
  // unbiased 0.33 and 0.17, coverage 0.63 and 0.62; with the guard but detection by segments
  // alone the oscillation's transient went unseen in 6.7 % of series (0.904 unbiased, 0.672
  // covered), now in 1.1 %.
  const Figure figures[] = {
      {"ar1", 0.6926, 0.9994}, {"two_scales", 0.6633, 0.9847}, {"oscillation", 0.6818, 0.9603}};
  std::uint64_t seed = 64000;
  for (const auto& f : figures) {
    const AutoFigures a = auto_window_figures(f.family, 50.0, 3.0, ++seed);
    expect_figure(a.coverage, f.coverage, f.family);
    EXPECT_NEAR(a.unbiased, f.unbiased, kBand) << f.family;
    EXPECT_GE(a.unbiased, 0.9) << f.family;
  }
}

// A transient of 1 standard error is where an automatic window stops keeping the promise: what it
// does not see it does not cut, and what is not cut keeps its whole bias. No rule that cuts at most
// 10 % of stationary series can see it in more series than the Neyman-Pearson bound (the matched
// filter, knowing the family's covariance and the decay's shape; scripts/transient_power_bound.py:
// 0.866 / 0.831 / 0.759 of AR(1) / two-scale / oscillating series at 50 slowest times, decay 5
// slowest times; 0.852 / 0.787 / 0.599 at the 9.0 / 7.4 / 4.2 % of stationary series the
// product's rule cuts); the bound reaches 0.9 only from a bias of 1.07 / 1.14 / 1.29 standard
// errors. The product's rule, which knows neither, leaves the settled figures below unbiased
// (0.71 / 0.62 / 0.35 of the bound at its own rates; 0.58 / 0.47 / 0.27 when only a single
// segment's failure detected a transient). What it leaves its error still covers, 0.655-0.678:
// the two halves' width, which batches of 40 counted correlation times keep at 50 slowest times,
// takes in part of the bias (with batches of 20: 0.630 / 0.642 on two scales / oscillation).
TEST(FamilyCoverage, AWeakTransientIsSeenNoMoreOftenThanTheBestTestAllows) {
  struct Figure {
    const char* family;
    double coverage, unbiased, bound;
  };
  const Figure figures[] = {{"ar1", 0.6784, 0.6085, 0.866},
                            {"two_scales", 0.6552, 0.4856, 0.831},
                            {"oscillation", 0.6692, 0.2116, 0.759}};
  std::uint64_t seed = 66000;
  for (const auto& f : figures) {
    const AutoFigures a = auto_window_figures(f.family, 50.0, 1.0, ++seed);
    expect_figure(a.coverage, f.coverage, f.family);
    EXPECT_NEAR(a.unbiased, f.unbiased, kBand) << f.family;
    EXPECT_LE(a.unbiased, f.bound + kBand) << f.family;
  }
}

namespace {

// The committed full-size 75 deg run's <w_p> rows (every 0.01 s; docs/results.md), from where the
// product's own cut puts the end of its start-up transient.
std::vector<double> plateau_75_degrees() {
  std::ifstream in(BOYCOTT_SOURCE_DIR "/docs/results/runs/9592e8d74a5a4760/timeseries.csv");
  std::string line;
  std::getline(in, line);  // time_s,mean_wp_m_s,...
  std::vector<double> w;
  while (std::getline(in, line)) w.push_back(std::stod(line.substr(line.find(',') + 1)));
  const auto cut = transient_end(w).start;
  return std::vector<double>(w.begin() + cut, w.end());
}

}  // namespace

TEST(FamilyCoverage, BlockBootstrapOfThe75DegreeRunsFluctuationsIsCovered) {
  // A real series' own correlation, whatever it is: the 75 deg plateau's fluctuations about their
  // mean, resampled as a circular block bootstrap (blocks of 5 tau_upper, random starts) into
  // series of `window` tau_int whose true mean is 0 (each block start equally likely, so the
  // resampled mean's expectation is the plateau's mean, subtracted). Correlation across a block's
  // end is lost, so blocks must be long against tau. Windows of at least 5 blocks: the plateau
  // holds only ~12 tau_upper, so its block means are few and far from normal (it drifts: halves
  // 192.1 and 187.4 mm/s), and a series of two blocks inherits that (0.61 at 20 tau_int, whose
  // two halves are the two blocks: when both come from the same part they agree by construction).
  auto x = plateau_75_degrees();
  ASSERT_GE(x.size(), 400u);
  const auto e = autocorrelation_error(x);
  for (double& v : x) v -= e.mean;
  const auto block = static_cast<std::size_t>(std::ceil(5.0 * e.tau_int_upper));
  std::printf("75 deg plateau: %zu rows, tau_int %.1f rows (upper %.1f), blocks of %zu rows\n", x.size(),
              e.tau_int, e.tau_int_upper, block);
  struct Figure {
    double window, settled;
  };
  for (const Figure f : {Figure{50.0, 0.6870}, Figure{100.0, 0.6767}}) {
    std::mt19937_64 rng(65000 + static_cast<int>(f.window));
    std::uniform_int_distribution<std::size_t> start(0, x.size() - 1);
    const auto n = static_cast<std::size_t>(f.window * e.tau_int);
    int covered = 0;
    for (int s = 0; s < kSeries; ++s) {
      std::vector<double> y;
      y.reserve(n + block);
      while (y.size() < n)
        for (std::size_t i = 0, a = start(rng); i < block && y.size() < n; ++i)
          y.push_back(x[(a + i) % x.size()]);
      const WindowError w = window_error(y, 0.0, static_cast<double>(n));
      covered += std::abs(w.e.mean) <= w.err.covering_error;
    }
    const double c = static_cast<double>(covered) / kSeries;
    std::printf("coverage, block bootstrap of the 75 deg plateau, %g tau_int: %.4f\n", f.window, c);
    expect_figure(c, f.settled, "75 deg bootstrap " + std::to_string(f.window));
  }
}
