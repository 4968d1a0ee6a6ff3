#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/statistics.hpp"

using namespace boycott;

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
