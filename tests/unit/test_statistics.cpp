#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "stats/autocorrelation.hpp"
#include "stats/precision_target.hpp"
#include "stats/running.hpp"

using namespace boycott::stats;

TEST(BatchMeans, StandardErrorOfCorrelatedSeriesMatchesAR1Theory) {
  // AR(1): x_n = phi x_{n-1} + eps, var(eps) = 1. Stationary variance 1/(1 - phi^2); the standard
  // error of the mean of N samples is sqrt(var (1 + phi)/(1 - phi) / N) for N >> correlation time.
  const double phi = 0.9;
  const long N = 1 << 20;
  const double var = 1.0 / (1.0 - phi * phi);
  const double expect = std::sqrt(var * (1.0 + phi) / (1.0 - phi) / N);
  double ratio_sum = 0.0;
  const int reps = 8;
  for (int r = 0; r < reps; ++r) {
    std::mt19937_64 rng(100 + r);
    std::normal_distribution<double> eps(0.0, 1.0);
    BatchMeans bm;
    double x = 0.0;
    for (long n = 0; n < N; ++n) {
      x = phi * x + eps(rng);
      bm.add(x);
    }
    EXPECT_GE(bm.batches(), 16);
    ratio_sum += bm.stderr_of_mean() / expect;
  }
  // Each estimate from 16-32 batches scatters by ~15 %; the mean of 8 is within 10 %, while the
  // naive sigma/sqrt(N) would be sqrt((1 - phi)/(1 + phi)) = 0.23 of the truth.
  EXPECT_NEAR(ratio_sum / reps, 1.0, 0.10);
}

TEST(Histogram, DensityIntegratesToTheFractionInside) {
  Histogram h(0.0, 1.0, 10);
  for (int i = 0; i < 1000; ++i) h.add((i + 0.5) / 1000.0);
  h.add(2.0);
  double integral = 0.0;
  for (double d : h.density()) integral += d * 0.1;
  EXPECT_NEAR(integral, 1000.0 / 1001.0, 1e-12);
}

namespace {

/// Many AR(1) series x_n = phi x_{n-1} + eps (started stationary), each holding `k` integrated
/// autocorrelation times tau_int = (1 + phi) / (2 (1 - phi)); the estimates against the exact
/// standard error of the mean of N samples,
///   var(mean) = var / N [1 + 2 sum_{t=1}^{N-1} (1 - t/N) phi^t],  var = 1 / (1 - phi^2).
struct Ar1Result {
  double mean_ratio = 0;     ///< mean over the series with an error of estimate / exact
  double warned = 0;         ///< fraction of series whose estimate is doubtful()
  double not_available = 0;  ///< fraction with no error (NaN)
};

Ar1Result ar1_estimates(double phi, double k, int series) {
  const double tau = (1.0 + phi) / (2.0 * (1.0 - phi));
  const auto n = static_cast<std::size_t>(std::lround(k * tau));
  const double var = 1.0 / (1.0 - phi * phi);
  double sum = 1.0;
  for (std::size_t t = 1; t < n; ++t) sum += 2.0 * (1.0 - double(t) / double(n)) * std::pow(phi, double(t));
  const double exact = std::sqrt(var * sum / double(n));
  Ar1Result r;
  int with_error = 0;
  for (int s = 0; s < series; ++s) {
    std::mt19937_64 rng(1000 + s);
    std::normal_distribution<double> eps(0.0, 1.0);
    std::vector<double> x(n);
    double v = eps(rng) * std::sqrt(var);
    for (auto& xi : x) xi = v = phi * v + eps(rng);
    const auto e = autocorrelation_error(x);
    r.warned += e.doubtful();
    if (std::isnan(e.stderr_of_mean)) {
      r.not_available += 1;
      continue;
    }
    r.mean_ratio += e.stderr_of_mean / exact;
    ++with_error;
  }
  r.mean_ratio /= with_error;
  r.warned /= series;
  r.not_available /= series;
  std::printf(
      "AR(1) phi %.2f, %.0f correlation times (N = %zu): estimate / exact %.3f, warned %.2f, n/a %.2f\n", phi,
      k, n, r.mean_ratio, r.warned, r.not_available);
  return r;
}

}  // namespace

TEST(AutocorrelationError, AR1MeanErrorWithin15PercentAt100CorrelationTimes) {
  for (double phi : {0.5, 0.9, 0.97}) {
    const auto r = ar1_estimates(phi, 100.0, 400);
    EXPECT_NEAR(r.mean_ratio, 1.0, 0.15) << "phi " << phi;
    EXPECT_EQ(r.not_available, 0.0);
    EXPECT_LT(r.warned, 0.1);
  }
  // 1000 correlation times: within 5 %.
  EXPECT_NEAR(ar1_estimates(0.9, 1000.0, 100).mean_ratio, 1.0, 0.05);
}

TEST(AutocorrelationError, AR1At20CorrelationTimesWithin30PercentAndWarned) {
  const auto r = ar1_estimates(0.9, 20.0, 400);
  EXPECT_NEAR(r.mean_ratio, 1.0, 0.30);
  // A window this short is flagged for most series (the estimate of tau scatters by ~50 %).
  EXPECT_GT(r.warned, 0.5);
  EXPECT_LT(r.not_available, 0.2);
}

TEST(AutocorrelationError, AR1At5CorrelationTimesWarnedAndNotAvailable) {
  // Five correlation times hold ~2.5 independent samples: the series cannot tell its own
  // correlation time reliably (some look like 20 correlation times), so this is a fraction.
  const auto r = ar1_estimates(0.9, 5.0, 400);
  EXPECT_GT(r.warned, 0.9);
  EXPECT_GT(r.not_available, 0.4);
  const auto r3 = ar1_estimates(0.9, 3.0, 400);
  EXPECT_GT(r3.warned, 0.9);
  EXPECT_GT(r3.not_available, 0.55);
}

TEST(AutocorrelationError, WhiteNoiseGivesThePlainStandardError) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 2.0);
  double ratio = 0.0, tau = 0.0;
  const int series = 400;
  const std::size_t n = 2000;
  for (int s = 0; s < series; ++s) {
    std::vector<double> x(n);
    for (auto& xi : x) xi = 5.0 + g(rng);
    double m = 0.0, ss = 0.0;
    for (double v : x) m += v / n;
    for (double v : x) ss += (v - m) * (v - m);
    const double plain = std::sqrt(ss / (n - 1.0) / n);
    const auto e = autocorrelation_error(x);
    EXPECT_FALSE(e.doubtful());
    ratio += e.stderr_of_mean / plain / series;
    tau += e.tau_int / series;
  }
  std::printf("white noise: estimate / plain standard error %.4f, tau_int %.3f\n", ratio, tau);
  EXPECT_NEAR(ratio, 1.0, 0.03);
  EXPECT_NEAR(tau, 0.5, 0.03);
  // A constant series: its mean is exact.
  const auto c = autocorrelation_error(std::vector<double>(100, 3.0));
  EXPECT_EQ(c.stderr_of_mean, 0.0);
  EXPECT_EQ(c.mean, 3.0);
}

TEST(PrecisionTarget, AResumedRunPlansItsLengthForItsOwnTargetFromTheSameFirstStage) {
  // A loose target (5 %) stops an AR(1) series (tau_int 10 steps, mean 1); its checkpointed state,
  // restored under the same target, stops at the same sample, and under a strict one (0.01 %)
  // plans a run 500^2 times as long in relative error terms and does not stop.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  const double phi = 19.0 / 21.0, sd = std::sqrt(1.0 - phi * phi);
  boycott::stats::PrecisionTarget loose(0.05);
  std::vector<double> x;
  double v = g(rng);
  while (x.size() < 200000) {
    x.push_back(1.0 + (v = phi * v + sd * g(rng)));
    if (loose.reached(x, 0.0, static_cast<double>(x.size()))) break;
  }
  ASSERT_LT(x.size(), 200000u);
  ASSERT_TRUE(loose.plan().set());
  boycott::stats::PrecisionTarget same(0.05), strict(1e-4);
  same.from_state(loose.to_state());
  strict.from_state(loose.to_state());
  EXPECT_EQ(same.plan().planned, loose.plan().planned);
  EXPECT_TRUE(same.reached(x, 0.0, static_cast<double>(x.size())));
  EXPECT_FALSE(strict.reached(x, 0.0, static_cast<double>(x.size())));
  EXPECT_GT(strict.plan().planned, 1000 * loose.plan().planned);
}
