#include "stats/window_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "stats/distributions.hpp"

namespace boycott::stats {

MeanError mean_error(const std::vector<double>& x, const AutocorrelationError& e, int max_batches) {
  MeanError m;
  m.stderr_of_mean = m.dof = m.covering_error = std::numeric_limits<double>::quiet_NaN();
  const std::size_t n = x.size();
  if (n < 8) return m;
  // As many batches as the conservative count of correlation spans (never more than of tau_int)
  // allows at kCorrelationTimesPerBatch each, two at least (also where no count could be made:
  // NaN compares false), kMaxBatches at most.
  const double count = e.batch_count();
  std::size_t k = 2;
  const double batches = std::floor(count / MeanError::kCorrelationTimesPerBatch);
  if (batches > 2.0)
    k = static_cast<std::size_t>(
        std::min({batches, static_cast<double>(n / 4), static_cast<double>(max_batches)}));
  // One correlation time (its upper end) left out at each border between batches, where the
  // neighbours' correlation lives; a tenth of the series at most, and where no count was made.
  const double most = MeanError::kGapFraction * static_cast<double>(n);
  const auto gaps = static_cast<std::size_t>(
      std::isfinite(count) && count > 0.0
          ? std::min(most, static_cast<double>(k - 1) * static_cast<double>(n) / count)
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

MeanError two_stage_error(const TwoStagePlan& plan, std::int64_t n) {
  MeanError m;
  m.stderr_of_mean = m.dof = m.covering_error = std::numeric_limits<double>::quiet_NaN();
  if (!plan.set() || n <= 0) return m;
  m.basis = MeanError::Basis::two_stage;
  m.dof = plan.dof0;
  m.batches = static_cast<int>(std::lround(plan.dof0)) + 1;
  m.stderr_of_mean = plan.se0 * std::sqrt(static_cast<double>(plan.n0) / static_cast<double>(n));
  m.covering_error = m.stderr_of_mean * one_sigma_t_factor(m.dof);
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
    case MeanError::Basis::two_stage:
      return "two_stage";
    case MeanError::Basis::none:
      break;
  }
  return "none";
}

WindowError window_error(const std::vector<double>& series, double window_from_s, double now_s,
                         const TwoStagePlan* plan) {
  WindowError w;
  w.e = autocorrelation_error(series);
  w.err = plan && plan->set() ? two_stage_error(*plan, static_cast<std::int64_t>(series.size()))
                              : mean_error(series, w.e);
  w.from_s = window_from_s;
  w.window_s = std::max(0.0, now_s - window_from_s);
  w.sample_s = series.empty() ? 0.0 : w.window_s / static_cast<double>(series.size());
  return w;
}

std::string window_warning(const WindowError& w, const std::string& what, double transient_end_s) {
  const auto& e = w.e;
  if (e.samples == 0) return "";
  std::string rests_on = "its error is not reported (fewer than 8 samples)";
  if (w.err.basis == MeanError::Basis::two_halves)
    rests_on =
        "its error comes from the difference of the window's two halves (1 degree of freedom; it "
        "covers ~2/3 of the time from ~10 correlation times on, less in shorter windows)";
  else if (w.err.basis == MeanError::Basis::batch_means)
    rests_on = fmt::format("its error comes from {} batch means ({} degrees of freedom)", w.err.batches,
                           w.err.batches - 1);
  else if (w.err.basis == MeanError::Basis::two_stage)
    rests_on = "its error is the two-stage one of the run's precision target";
  if (!std::isfinite(e.tau_int))
    return fmt::format(
        "the averaging window ({:.4g} s, {} samples) gives no estimate of the correlation time of {}: {}",
        w.window_s, e.samples, what, rests_on);
  if (!e.doubtful()) return "";
  std::string advice = "run longer or average from earlier";
  if (std::isfinite(transient_end_s))
    advice =
        transient_end_s < w.from_s - 0.5 * w.sample_s
            ? fmt::format("run longer, or average from {:.3g} s, where the detected start-up transient ends",
                          transient_end_s)
            : fmt::format(
                  "run longer (the detected start-up transient ends at {:.3g} s: averaging from "
                  "earlier would take it in)",
                  transient_end_s);
  // Doubtful with enough correlation times: only the autocorrelation window failed to close.
  const bool few = !(e.correlation_times >= AutocorrelationError::kWarnCorrelationTimes);
  return fmt::format(
      "the averaging window ({:.4g} s) holds {}{:.1f} correlation times of {} (tau_int {:.3g} s, at most "
      "{:.3g} s{}); {}: {}",
      w.window_s, few ? "only " : "", e.correlation_times, what, w.correlation_time_s(),
      w.correlation_time_upper_s(), e.window_closed ? "" : ", the autocorrelation window did not close",
      few ? fmt::format("below {:g} {}", AutocorrelationError::kWarnCorrelationTimes, rests_on) : rests_on,
      advice);
}

}  // namespace boycott::stats
