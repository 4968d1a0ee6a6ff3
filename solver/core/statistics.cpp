#include "core/statistics.hpp"

#include "core/distributions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace boycott {

void BatchMeans::add(double x) {
  ++count_;
  total_ += x;
  open_sum_ += x;
  if (++open_n_ < batch_len_) return;
  sums_.push_back(open_sum_);
  open_sum_ = 0.0;
  open_n_ = 0;
  if (static_cast<int>(sums_.size()) >= 2 * min_batches_) {
    std::vector<double> merged(sums_.size() / 2);
    for (std::size_t b = 0; b < merged.size(); ++b) merged[b] = sums_[2 * b] + sums_[2 * b + 1];
    sums_.swap(merged);
    batch_len_ *= 2;
  }
}

double BatchMeans::mean() const {
  return count_ ? total_ / static_cast<double>(count_) : std::numeric_limits<double>::quiet_NaN();
}

double BatchMeans::stderr_of_mean() const {
  const std::size_t B = sums_.size();
  if (B < 4) return std::numeric_limits<double>::quiet_NaN();
  const double L = static_cast<double>(batch_len_);
  double m = 0.0;
  for (double s : sums_) m += s / L;
  m /= static_cast<double>(B);
  double v = 0.0;
  for (double s : sums_) v += (s / L - m) * (s / L - m);
  v /= static_cast<double>(B - 1);
  return std::sqrt(v / static_cast<double>(B));
}

AutocorrelationError autocorrelation_error(const std::vector<double>& x) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  using AE = AutocorrelationError;
  AE e;
  const std::size_t n = x.size();
  e.samples = static_cast<std::int64_t>(n);
  double sum = 0.0;
  for (double v : x) sum += v;
  e.mean = n ? sum / static_cast<double>(n) : kNaN;
  e.stderr_of_mean = e.tau_int = e.tau_int_upper = e.effective_samples = e.correlation_times = e.dof =
      e.covering_error = kNaN;
  if (n < 8) return e;
  const double N = static_cast<double>(n);
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = x[i] - e.mean;
  // Autocovariances four lags to a pass over y: each lag's sum keeps its own order of additions
  // (the same bits as a pass per lag), in four independent chains of additions instead of one
  // (a chain waits on each addition's latency) and with y read once for four lags.
  constexpr std::size_t kLags = 4;
  std::vector<double> cov;
  auto autocov = [&](std::size_t t) {
    while (cov.size() <= t) {
      const std::size_t t0 = cov.size(), lags = std::min(kLags, n - t0);
      double acc[kLags] = {0.0, 0.0, 0.0, 0.0};
      const std::size_t common = n - (t0 + lags - 1);  // i below this: every lag of the pass has i + t < n
      for (std::size_t i = 0; i < common; ++i)
        for (std::size_t k = 0; k < kLags; ++k)
          if (k < lags) acc[k] += y[i] * y[i + t0 + k];
      for (std::size_t k = 0; k < lags; ++k) {
        for (std::size_t i = common; i + t0 + k < n; ++i) acc[k] += y[i] * y[i + t0 + k];
        cov.push_back(acc[k] / static_cast<double>(n - t0 - k));
      }
    }
    return cov[t];
  };
  const double c0 = autocov(0);
  if (!(c0 > 0.0)) {  // a constant series: its mean is exact
    e.stderr_of_mean = e.covering_error = 0.0;
    e.dof = std::numeric_limits<double>::infinity();
    e.tau_int = e.tau_int_upper = 0.5;
    e.effective_samples = N;
    e.correlation_times = std::numeric_limits<double>::infinity();
    e.window_closed = true;
    return e;
  }
  // var(m) and tau_int for the window M, with the mean's bias solved for (see the header).
  double S = c0;  // sum over |t| <= M of C(t)
  auto var_of_mean = [&](std::size_t M) { return S / (N - 2.0 * static_cast<double>(M) - 1.0); };
  auto tau_of = [&](double V) { return N * V / (2.0 * (c0 + V)); };
  const std::size_t max_window = (n - 1) / 4;
  std::size_t M = 0;
  for (std::size_t m = 1; m <= max_window; ++m) {
    S += 2.0 * autocov(m);
    M = m;
    if (static_cast<double>(m) >= AE::kWindowFactor * tau_of(var_of_mean(m))) {
      e.window_closed = true;
      break;
    }
  }
  e.window = static_cast<std::int64_t>(M);
  const double V = var_of_mean(M);
  if (!(V > 0.0)) return e;  // anticorrelated noise summed below zero: no estimate
  e.tau_int = tau_of(V);
  e.tau_int_upper = e.tau_int * (1.0 + std::sqrt(2.0 * (2.0 * static_cast<double>(M) + 1.0) / N));
  e.effective_samples = N / (2.0 * e.tau_int);
  e.correlation_times = N / e.tau_int_upper;
  e.dof = N / (2.0 * static_cast<double>(M) + 1.0);
  if (e.correlation_times >= AE::kMinCorrelationTimes) {
    e.stderr_of_mean = std::sqrt(V);
    e.covering_error = e.stderr_of_mean * one_sigma_t_factor(e.dof);
  }
  return e;
}

MeanError mean_error(const std::vector<double>& x, const AutocorrelationError& e) {
  MeanError m;
  m.stderr_of_mean = m.dof = m.covering_error = std::numeric_limits<double>::quiet_NaN();
  const std::size_t n = x.size();
  if (n < 8) return m;
  // As many batches as the conservative count allows at kCorrelationTimesPerBatch each, two at
  // least (also where no count could be made: NaN compares false).
  std::size_t k = 2;
  const double batches = std::floor(e.correlation_times / MeanError::kCorrelationTimesPerBatch);
  if (batches > 2.0) k = static_cast<std::size_t>(std::min(batches, static_cast<double>(n / 4)));
  // One correlation time (its upper end) left out at each border between batches, where the
  // neighbours' correlation lives; a tenth of the series at most, and where no count was made.
  const double most = MeanError::kGapFraction * static_cast<double>(n);
  const auto gaps = static_cast<std::size_t>(
      std::isfinite(e.correlation_times) && e.correlation_times > 0.0
          ? std::min(most, static_cast<double>(k - 1) * static_cast<double>(n) / e.correlation_times)
          : most);
  const std::size_t len = (n - gaps) / k;
  // Batch j starts at j (n - len) / (k - 1): the first at 0, the last ending at n, the samples
  // left between them spread as gaps.
  std::vector<double> means(k);
  for (std::size_t j = 0; j < k; ++j) {
    const std::size_t from = (n - len) * j / (k - 1);
    double sum = 0.0;
    for (std::size_t i = from; i < from + len; ++i) sum += x[i];
    means[j] = sum / static_cast<double>(len);
  }
  double mean = 0.0;
  for (double v : means) mean += v;
  mean /= static_cast<double>(k);
  double ss = 0.0;
  for (double v : means) ss += (v - mean) * (v - mean);
  m.basis = k == 2 ? MeanError::Basis::two_halves : MeanError::Basis::batch_means;
  m.batches = static_cast<int>(k);
  m.dof = static_cast<double>(k - 1);
  m.stderr_of_mean = std::sqrt(ss / (m.dof * static_cast<double>(k)));
  m.covering_error = m.stderr_of_mean * one_sigma_t_factor(m.dof);
  return m;
}

MeanError sokal_mean_error(const AutocorrelationError& e) {
  MeanError m;
  m.basis = std::isfinite(e.covering_error) ? MeanError::Basis::autocorrelation : MeanError::Basis::none;
  m.stderr_of_mean = e.stderr_of_mean;
  m.dof = e.dof;
  m.covering_error = e.covering_error;
  return m;
}

const char* error_method_name(MeanError::Basis b) {
  switch (b) {
    case MeanError::Basis::autocorrelation:
      return "sokal_autocorrelation";
    case MeanError::Basis::batch_means:
      return "gapped_batch_means";
    case MeanError::Basis::two_halves:
      return "two_halves";
    case MeanError::Basis::none:
      break;
  }
  return "none";
}

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

void Histogram::add(double x, double w) {
  total_ += w;
  if (!(x >= lo_ && x < hi_)) {
    outside_ += w;
    return;
  }
  counts_[static_cast<std::size_t>((x - lo_) / (hi_ - lo_) * counts_.size())] += w;
}

std::vector<double> Histogram::density() const {
  std::vector<double> d(counts_.size(), 0.0);
  const double width = (hi_ - lo_) / counts_.size();
  if (total_ <= 0.0) return d;
  for (std::size_t b = 0; b < d.size(); ++b) d[b] = counts_[b] / (total_ * width);
  return d;
}

}  // namespace boycott
