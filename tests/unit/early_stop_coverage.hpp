#pragma once
// The error a run stopped by time.target_rel_error reports, tried on AR(1) series (tau_int 10 steps,
// unit variance, true mean -1): the share of stopped series whose stated interval holds the true
// mean. Shared by the quick check (test_run_statistics.cpp) and the 10 000-series figures
// (test_coverage_families.cpp, label long).
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "stats/precision_target.hpp"
#include "stats/window_error.hpp"

namespace boycott::testing {

struct EarlyStopFigures {
  int stopped = 0, covered = 0;
  double mean_tau = 0.0;  ///< the stopped series' mean length, in tau_int
  double coverage() const { return stopped > 0 ? static_cast<double>(covered) / stopped : 0.0; }
};

inline EarlyStopFigures ar1_early_stop_coverage(double target, int series, std::uint64_t seed) {
  constexpr double kTau = 10.0;
  const double phi = (2.0 * kTau - 1.0) / (2.0 * kTau + 1.0), sd = std::sqrt(1.0 - phi * phi);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  EarlyStopFigures f;
  double samples = 0.0;
  for (int s = 0; s < series; ++s) {
    stats::PrecisionTarget stop(target);
    std::vector<double> x;
    double v = g(rng);
    // A run that never meets the target ends at 100 000 samples (time.end); not counted.
    while (x.size() < 100000) {
      v = phi * v + sd * g(rng);
      x.push_back(-1.0 + v);
      if (stop.reached(x, 0.0, static_cast<double>(x.size()))) break;
    }
    if (x.size() >= 100000) continue;
    ++f.stopped;
    samples += static_cast<double>(x.size());
    // The error the run reports (summary.json's error_m_s of a run the target stopped).
    const auto w = stats::window_error(x, 0.0, static_cast<double>(x.size()), &stop.plan());
    f.covered += std::abs(w.e.mean + 1.0) <= w.err.covering_error;
  }
  f.mean_tau = f.stopped > 0 ? samples / f.stopped / kTau : 0.0;
  return f;
}

}  // namespace boycott::testing
