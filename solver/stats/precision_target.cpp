#include "stats/precision_target.hpp"

#include <algorithm>
#include <cmath>

#include "stats/distributions.hpp"
#include "stats/transient.hpp"

namespace boycott::stats {

bool PrecisionTarget::reached(const std::vector<double>& series, double window_from_s, double now_s) {
  if (!active()) return false;
  const auto n = static_cast<std::int64_t>(series.size());
  if (plan_.set()) return n >= plan_.planned;
  // Before the first stage is fixed, checks every 2 % of the samples (at least 25): their cost
  // grows with the window; after, nothing until the first stage.
  if (first_stage_at_ > 0 ? n < first_stage_at_ : n < next_check_) return false;
  if (first_stage_at_ == 0) next_check_ = n + std::max<std::int64_t>(25, n / 50);
  // The run's own window: from where the transient is detected to end (no step lengths here).
  std::int64_t cut = 0;
  if (cut_transient_) {
    const ChosenWindow c =
        cut_at_transient(StepSeries{{}, {}, {}, true, false}, series, window_from_s, now_s);
    cut = static_cast<std::int64_t>(series.size() - c.window.size());
  }
  const std::vector<double> x(series.begin() + cut, series.end());
  const auto nx = static_cast<std::int64_t>(x.size());
  if (first_stage_at_ == 0) {
    const AutocorrelationError e = autocorrelation_error(x);
    last_rel_error_ = std::abs(e.covering_error / e.mean);
    // Counted on tau_int; on spans only where tau_int has no estimate (an oscillation whose lobes
    // cancel): the span's sum of |rho| gathers noise over its long window, so at hundreds of
    // samples per correlation time (a run's <w_p>, every step) it counts far fewer than there are
    // and put the first stage past the end of a run that holds 500 correlation times.
    const double count = std::isfinite(e.correlation_times) ? e.correlation_times : e.span_times;
    if (count >= kMinCorrelationTimes)
      first_stage_at_ =
          cut + static_cast<std::int64_t>(std::ceil(kFirstStageFactor * static_cast<double>(nx)));
    return false;
  }
  // The first stage: the plan, fixed once.
  const MeanError m = mean_error(x, autocorrelation_error(x), kFirstStageMaxBatches);
  double mean = 0.0;
  for (double v : x) mean += v / static_cast<double>(nx);
  plan_.n0 = nx;
  plan_.se0 = m.stderr_of_mean;
  plan_.dof0 = m.dof;
  plan_.mean0 = mean;
  plan_.cut = cut;
  plan_length();
  return n >= plan_.planned;
}

void PrecisionTarget::plan_length() {
  // n0 (t_dof0 se0 / (target |mean0|))^2 samples, at least n0 (no estimate: never).
  const double rel0 = se0_rel_covering();
  const double need = std::pow(rel0 / target_, 2) * static_cast<double>(plan_.n0);
  plan_.planned =
      plan_.cut + std::max<std::int64_t>(plan_.n0, std::isfinite(need)
                                                       ? static_cast<std::int64_t>(std::ceil(need))
                                                       : std::numeric_limits<std::int64_t>::max() / 2);
  last_rel_error_ =
      rel0 * std::sqrt(static_cast<double>(plan_.n0) / static_cast<double>(plan_.planned - plan_.cut));
}

double PrecisionTarget::se0_rel_covering() const {
  return std::abs(plan_.se0 * one_sigma_t_factor(plan_.dof0) / plan_.mean0);
}

std::vector<double> PrecisionTarget::to_state() const {
  return {static_cast<double>(next_check_),
          static_cast<double>(first_stage_at_),
          static_cast<double>(plan_.n0),
          plan_.se0,
          plan_.dof0,
          plan_.mean0,
          static_cast<double>(plan_.planned),
          static_cast<double>(plan_.cut)};
}

void PrecisionTarget::from_state(const std::vector<double>& v) {
  if (v.empty()) return;
  next_check_ = static_cast<std::int64_t>(v[0]);
  if (v.size() < 8) return;  // a build before the two-stage plan: the plan starts from here
  first_stage_at_ = static_cast<std::int64_t>(v[1]);
  plan_.n0 = static_cast<std::int64_t>(v[2]);
  plan_.se0 = v[3];
  plan_.dof0 = v[4];
  plan_.mean0 = v[5];
  plan_.planned = static_cast<std::int64_t>(v[6]);
  plan_.cut = static_cast<std::int64_t>(v[7]);
  // The length for this run's target (a resumed run may ask another): Stein's plan from the
  // same first stage.
  if (plan_.set() && active()) plan_length();
}

}  // namespace boycott::stats
