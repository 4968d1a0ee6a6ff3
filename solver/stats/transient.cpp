#include "stats/transient.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stats/autocorrelation.hpp"

namespace boycott::stats {

TransientEnd transient_end(const std::vector<double>& x) {
  TransientEnd cut;
  const auto n = static_cast<std::int64_t>(x.size());
  if (n < 16) return cut;
  const std::vector<double> ref(x.begin() + n / 2, x.end());
  const auto e = autocorrelation_error(ref);
  if (!std::isfinite(e.tau_int_upper)) return cut;
  cut.estimated = true;
  double var = 0.0;
  for (double v : ref) var += (v - e.mean) * (v - e.mean);
  var /= static_cast<double>(ref.size());
  // The long-run variance of a sample mean, at the upper end of tau_int: a test that errs towards
  // calling a segment stationary (its cuts then come from the data, not from an estimate that dipped).
  const double long_run_var = 2.0 * var * e.tau_int_upper;
  const std::int64_t len = std::max<std::int64_t>(1, n / (2 * TransientEnd::kSegments));
  const std::int64_t segments = std::min<std::int64_t>(TransientEnd::kSegments, n / 2 / len);
  const double diff_var = long_run_var * (1.0 / static_cast<double>(len) + 1.0 / static_cast<double>(ref.size()));
  std::int64_t end = 0;
  for (std::int64_t j = 0, clean = 0; j < segments && clean < 2; ++j) {
    double mean = 0.0, spread = 0.0;
    for (std::int64_t i = j * len; i < (j + 1) * len; ++i) {
      mean += x[static_cast<std::size_t>(i)];
      spread += (x[static_cast<std::size_t>(i)] - e.mean) * (x[static_cast<std::size_t>(i)] - e.mean);
    }
    mean /= static_cast<double>(len);
    spread /= static_cast<double>(len);
    const double d = std::abs(mean - e.mean);
    const bool differs = (d > 0.0 && d * d > TransientEnd::kMeanZ * TransientEnd::kMeanZ * diff_var) ||
                         spread > TransientEnd::kSpreadFactor * var;
    if (differs) {
      end = j + 1;
      clean = 0;
    } else {
      ++clean;
    }
  }
  cut.detected = end * len;
  cut.start = std::min<std::int64_t>(n / 2, std::llround(TransientEnd::kGuard * static_cast<double>(cut.detected)));
  return cut;
}

bool transient_biases_mean(const std::vector<double>& x, std::int64_t from, std::int64_t start) {
  if (start <= from) return false;
  const auto tail = autocorrelation_error(std::vector<double>(x.begin() + start, x.end()));
  if (!std::isfinite(tail.tau_int)) return false;
  double head_mean = 0.0, tail_var = 0.0;
  for (auto i = from; i < start; ++i) head_mean += x[i] / static_cast<double>(start - from);
  for (auto i = static_cast<std::size_t>(start); i < x.size(); ++i)
    tail_var += (x[i] - tail.mean) * (x[i] - tail.mean);
  tail_var /= static_cast<double>(x.size() - static_cast<std::size_t>(start));
  // Under the hypothesis that the head is more of the stationary part, its mean scatters with the
  // tail's variance and correlation time (a trend in the head would inflate its own estimate).
  const double head_samples = std::max(1.0, static_cast<double>(start - from) / (2.0 * tail.tau_int));
  const double var_diff = tail_var / head_samples + tail.stderr_of_mean * tail.stderr_of_mean;
  return std::abs(head_mean - tail.mean) > kTransientSignificance * std::sqrt(var_diff);
}

ChosenWindow cut_at_transient(const StepSeries& s, const std::vector<double>& window, double collected_from_s,
                              double now_s) {
  const TransientEnd cut = transient_end(window);
  return cut_window_at(s, window, collected_from_s, now_s, cut.estimated ? cut.start : 0);
}

ChosenWindow cut_window_at(const StepSeries& s, const std::vector<double>& window, double collected_from_s,
                           double now_s, std::int64_t cut) {
  ChosenWindow c{s, window, collected_from_s};
  if (cut <= 0) return c;
  const auto k = std::min(static_cast<std::size_t>(cut), window.size());
  c.steps.before.insert(c.steps.before.end(), window.begin(),
                        window.begin() + static_cast<std::ptrdiff_t>(k));
  c.window.erase(c.window.begin(), c.window.begin() + static_cast<std::ptrdiff_t>(k));
  if (s.dt_whole && s.window_dt.size() == window.size()) {
    for (std::size_t i = 0; i < k; ++i) c.from_s += s.window_dt[i];
    c.steps.before_dt.insert(c.steps.before_dt.end(), s.window_dt.begin(),
                             s.window_dt.begin() + static_cast<std::ptrdiff_t>(k));
    c.steps.window_dt.erase(c.steps.window_dt.begin(),
                            c.steps.window_dt.begin() + static_cast<std::ptrdiff_t>(k));
  } else {  // no step lengths: the cut's time from the mean step
    c.from_s += (now_s - collected_from_s) * static_cast<double>(k) / static_cast<double>(window.size());
    c.steps.dt_whole = false;
    c.steps.window_dt.clear();
  }
  return c;
}

}  // namespace boycott::stats
