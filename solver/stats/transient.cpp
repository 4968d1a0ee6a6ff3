#include "stats/transient.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "stats/autocorrelation.hpp"

namespace boycott::stats {

namespace {

// Batch means of x: `block` samples each, the incomplete last one left out.
std::vector<double> batch_means(const std::vector<double>& x, std::int64_t block) {
  std::vector<double> b(x.size() / static_cast<std::size_t>(block));
  for (std::size_t i = 0; i < b.size(); ++i) {
    double s = 0.0;
    for (std::int64_t k = 0; k < block; ++k) s += x[i * block + k];
    b[i] = s / static_cast<double>(block);
  }
  return b;
}

// The start in [0, b.size() / 2] with the most effective samples, (n - t0) / (2 tau_int), on a
// grid of kCandidates starts, and that count; none where no start gives an estimate.
struct EffectiveStart {
  std::int64_t start = 0;
  double effective_samples = 0.0;
};
std::optional<EffectiveStart> most_effective_samples_start(const std::vector<double>& b) {
  const auto nb = static_cast<std::int64_t>(b.size());
  std::optional<EffectiveStart> best;
  for (int c = 0; c <= TransientEnd::kCandidates; ++c) {
    const std::int64_t t0 = nb / 2 * c / TransientEnd::kCandidates;
    const double neff = autocorrelation_error(std::vector<double>(b.begin() + t0, b.end())).effective_samples;
    if (std::isfinite(neff) && !(best && neff <= best->effective_samples)) best = EffectiveStart{t0, neff};
  }
  return best;
}

// MSER: the start in [0, b.size() / 2] with the least marginal standard error,
// sum over i >= t0 of (b_i - mean)^2 / (n - t0)^2, from suffix sums in O(n).
std::int64_t mser_start(const std::vector<double>& b) {
  const auto nb = static_cast<std::int64_t>(b.size());
  std::vector<double> s1(b.size() + 1, 0.0), s2(b.size() + 1, 0.0);
  for (std::int64_t i = nb - 1; i >= 0; --i) {
    s1[i] = s1[i + 1] + b[i];
    s2[i] = s2[i + 1] + b[i] * b[i];
  }
  double best = std::numeric_limits<double>::infinity();
  std::int64_t start = 0;
  for (std::int64_t t0 = 0; t0 <= nb / 2; ++t0) {
    const double m = static_cast<double>(nb - t0), mean = s1[t0] / m;
    const double mser = std::max(0.0, s2[t0] / m - mean * mean) / m;
    if (mser < best) {
      best = mser;
      start = t0;
    }
  }
  return start;
}

}  // namespace

TransientEnd transient_end(const std::vector<double>& x) {
  TransientEnd cut;
  cut.effective_samples = std::numeric_limits<double>::quiet_NaN();
  const auto n = static_cast<std::int64_t>(x.size());
  if (n < 16) return cut;
  // The correlation time survives blocking to kMaxBlocks; MSER-5 batches at least 5 samples.
  const std::int64_t block = (n + TransientEnd::kMaxBlocks - 1) / TransientEnd::kMaxBlocks;
  const std::int64_t batch = std::max(TransientEnd::kBatch, block);
  const std::vector<double> b = batch_means(x, block);
  const auto effective_start = most_effective_samples_start(b);
  if (!effective_start) return cut;
  const std::int64_t mser =
      batch == block ? mser_start(b) : mser_start(batch_means(x, batch)) * batch / block;
  const std::int64_t start_block = std::max(effective_start->start, mser);
  cut.start = start_block * block;
  // Counted on the blocks (blocking keeps the count); MSER's later cut is counted anew.
  cut.effective_samples =
      start_block == effective_start->start
          ? effective_start->effective_samples
          : autocorrelation_error(std::vector<double>(b.begin() + start_block, b.end())).effective_samples;
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
  ChosenWindow c{s, window, collected_from_s};
  const TransientEnd cut = transient_end(window);
  if (!std::isfinite(cut.effective_samples) || cut.start <= 0) return c;
  const auto k = static_cast<std::size_t>(cut.start);
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
