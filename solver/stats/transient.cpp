#include "stats/transient.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stats/autocorrelation.hpp"
#include "stats/distributions.hpp"

namespace boycott::stats {

namespace {

// The mean of x[from, from + len).
double segment_mean(const std::vector<double>& x, std::int64_t from, std::int64_t len) {
  double m = 0.0;
  for (std::int64_t i = from; i < from + len; ++i) m += x[static_cast<std::size_t>(i)];
  return m / static_cast<double>(len);
}

// The reference: the last `count` segments of `len` samples (the last one ending at the series'
// end), their mean, the scatter of their means (the variance of one segment's mean, estimated
// without a model of the correlation) and the variance of the samples.
struct Reference {
  std::int64_t count = 0;
  double mean = 0.0, segment_var = 0.0, var = 0.0;
};
Reference reference(const std::vector<double>& x, std::int64_t len, std::int64_t count) {
  Reference r{count};
  const auto n = static_cast<std::int64_t>(x.size());
  std::vector<double> means(static_cast<std::size_t>(count));
  for (std::int64_t j = 0; j < count; ++j) {
    means[static_cast<std::size_t>(j)] = segment_mean(x, n - (j + 1) * len, len);
    r.mean += means[static_cast<std::size_t>(j)] / static_cast<double>(count);
  }
  for (double m : means) r.segment_var += (m - r.mean) * (m - r.mean) / static_cast<double>(count - 1);
  for (std::int64_t i = n - count * len; i < n; ++i)
    r.var += (x[static_cast<std::size_t>(i)] - r.mean) * (x[static_cast<std::size_t>(i)] - r.mean) /
             static_cast<double>(count * len);
  return r;
}

}  // namespace

TransientEnd transient_end(const std::vector<double>& x) {
  TransientEnd cut;
  const auto n = static_cast<std::int64_t>(x.size());
  if (n < 16) return cut;
  const std::int64_t len = std::max<std::int64_t>(1, n / (2 * TransientEnd::kSegments));
  const std::int64_t refs = (n - n / 2) / len;
  if (refs < 4) return cut;
  const Reference ref = reference(x, len, refs);
  if (!(ref.segment_var > 0.0)) return cut;
  cut.estimated = true;
  // A segment's mean less the reference's: the segment's variance and the reference's, as if
  // independent; Student's t at the reference's refs - 1 degrees of freedom.
  const double q = student_t_quantile(1.0 - TransientEnd::kFalseAlarm / 2.0, static_cast<double>(refs - 1));
  const double diff_var = ref.segment_var * (1.0 + 1.0 / static_cast<double>(refs));
  const std::int64_t segments = std::min<std::int64_t>(TransientEnd::kSegments, (n - refs * len) / len);
  std::int64_t end = 0;
  for (std::int64_t j = 0, clean = 0; j < segments && clean < 2; ++j) {
    const double m = segment_mean(x, j * len, len);
    double spread = 0.0;
    for (std::int64_t i = j * len; i < (j + 1) * len; ++i)
      spread += (x[static_cast<std::size_t>(i)] - m) * (x[static_cast<std::size_t>(i)] - m) /
                static_cast<double>(len);
    const bool differs =
        (m - ref.mean) * (m - ref.mean) > q * q * diff_var || spread > TransientEnd::kSpreadFactor * ref.var;
    clean = differs ? 0 : clean + 1;
    if (differs) end = j + 1;
  }
  cut.detected = end * len;
  if (end > 0) {
    // The reference's correlation span, its upper end (samples): how long the series remembers.
    const AutocorrelationError e = autocorrelation_error(std::vector<double>(x.end() - refs * len, x.end()));
    const double span = std::isfinite(e.span_times) && e.span_times > 0.0
                            ? static_cast<double>(refs * len) / e.span_times
                            : 0.0;
    cut.start = std::min<std::int64_t>(n / 2, cut.detected + std::llround(TransientEnd::kGuardSpans * span));
  }
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
