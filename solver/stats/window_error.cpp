#include "stats/window_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stats/distributions.hpp"

namespace boycott::stats {

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

WindowError window_error(const std::vector<double>& series, double window_from_s, double now_s,
                         bool stopped_by_target) {
  WindowError w;
  w.e = autocorrelation_error(series);
  w.err = stopped_by_target ? sokal_mean_error(w.e) : mean_error(series, w.e);
  w.from_s = window_from_s;
  w.window_s = std::max(0.0, now_s - window_from_s);
  w.sample_s = series.empty() ? 0.0 : w.window_s / static_cast<double>(series.size());
  return w;
}

}  // namespace boycott::stats
