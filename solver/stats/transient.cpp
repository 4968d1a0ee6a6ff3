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

// chi^2 with one degree of freedom at 99 %: a decay that fits the segment means no better than
// that beyond a common offset is noise. As a detector of its own (where no segment fails) it
// looks at 400 decay times and correlated segments, so it fires on more than 1 % of stationary
// series: it raised the share of them cut from 6.1 / 5.2 / 3.8 % (segments alone) to 9.0 / 7.4 /
// 4.2 % of AR(1) / two-scale / oscillating series, within the promised 10 %.
constexpr double kDecayShown = 6.63;

// Where the modelled rest of a detected transient no longer biases what is kept: the first
// half's segment means less the reference's, e_j, fitted by A rho^j (the shape of a relaxation
// at its slowest rate), rho at the slow end of its profile interval (the largest decay time whose
// squared residuals exceed the best fit's by at most kDecayProfile segment variances), so that an
// uncertain decay errs late. Returns the first cut at which the model's rest, averaged over the
// kept samples, is below kResidualBias of the kept mean's standard error (segment_var len /
// kept)^1/2; half the series when none is; 0 where no decay shows beyond the segments' scatter.
// The fit is not rejected for a poor shape: a head that no exponential follows well gets a slow
// end that errs late, which costs samples, not bias.
std::int64_t cut_past_fitted_decay(const std::vector<double>& x, std::int64_t len, std::int64_t segments,
                                   const Reference& ref) {
  const auto n = static_cast<std::int64_t>(x.size());
  std::vector<double> e(static_cast<std::size_t>(segments));
  for (std::int64_t j = 0; j < segments; ++j)
    e[static_cast<std::size_t>(j)] = segment_mean(x, j * len, len) - ref.mean;
  // Decay times of 0.05-500 segments, 100 per decade: for each, A by least squares and the
  // squared residuals.
  struct Fit {
    double rho = 0.0, amplitude = 0.0, residuals = 0.0;
  };
  constexpr int kGrid = 400;
  std::vector<Fit> fits(kGrid + 1);
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= kGrid; ++k) {
    const double rho = std::exp(-1.0 / (0.05 * std::pow(10.0, 4.0 * k / kGrid)));
    double se = 0.0, ss = 0.0, ee = 0.0, p = 1.0;
    for (double ej : e) {
      se += ej * p;
      ss += p * p;
      ee += ej * ej;
      p *= rho;
    }
    fits[static_cast<std::size_t>(k)] = {rho, se / ss, ee - se * se / ss};
    best = std::min(best, ee - se * se / ss);
  }
  // A stationary series' segment means differ from the reference's by a common offset (the
  // reference mean's own error) plus noise: a decay must fit them better than the offset does by
  // more than their scatter allows, else (a head detected by its spread alone, a swing that
  // averages out within a segment) the spans' guard alone.
  double sum = 0.0, squares = 0.0;
  for (double ej : e) sum += ej, squares += ej * ej;
  const double offset_residuals = squares - sum * sum / static_cast<double>(segments);
  if (offset_residuals - best < kDecayShown * ref.segment_var) return 0;
  Fit slow;
  for (const Fit& f : fits)
    if (f.residuals - best <= TransientEnd::kDecayProfile * ref.segment_var) slow = f;
  // The model per sample: a exp(-i / D) with D = len / ln(1 / rho), whose segment means are
  // A rho^j; what is left of it from sample k on sums to A len rho^(k / len) / (1 - rho). Cuts
  // are tried every tenth of a segment, so that a decay shorter than a segment is not cut at the
  // next segment's end.
  const std::int64_t step = std::max<std::int64_t>(1, len / 10);
  for (std::int64_t k = 0; k < n / 2; k += step) {
    const double kept = static_cast<double>(n - k);
    const double bias = std::abs(slow.amplitude) * static_cast<double>(len) *
                        std::pow(slow.rho, static_cast<double>(k) / static_cast<double>(len)) /
                        (1.0 - slow.rho) / kept;
    if (bias < TransientEnd::kResidualBias * std::sqrt(ref.segment_var * static_cast<double>(len) / kept))
      return k;
  }
  return n / 2;
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
  // The fit pools the segments: a weak transient spread over several of them (one that biases
  // the mean by about one standard error) shows there far more often than in any one segment.
  const std::int64_t past_decay = cut_past_fitted_decay(x, len, segments, ref);
  if (end == 0) {
    cut.start = past_decay;
    cut.detected = past_decay;
    return cut;
  }
  cut.detected = end * len;
  // The reference's correlation span, its upper end (samples): how long the series remembers.
  const AutocorrelationError e = autocorrelation_error(std::vector<double>(x.end() - refs * len, x.end()));
  const double span = std::isfinite(e.span_times) && e.span_times > 0.0
                          ? static_cast<double>(refs * len) / e.span_times
                          : 0.0;
  const std::int64_t guarded =
      std::min<std::int64_t>(n / 2, cut.detected + std::llround(TransientEnd::kGuardSpans * span));
  cut.start = std::max(guarded, past_decay);
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
