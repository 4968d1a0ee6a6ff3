#include "stats/precision_target.hpp"

#include <algorithm>
#include <cmath>

#include "stats/transient.hpp"
#include "stats/window_error.hpp"

namespace boycott::stats {

bool PrecisionTarget::reached(const std::vector<double>& series, double window_from_s, double now_s) {
  if (!active() || static_cast<std::int64_t>(series.size()) < next_check_) return false;
  // Checks every 2 % of the samples (at least 25): their cost grows with the window.
  const auto n = static_cast<std::int64_t>(series.size());
  next_check_ = n + std::max<std::int64_t>(25, n / 50);
  // The run's own window: judged from where the transient is detected to end (no step lengths
  // here: the cut's time from the mean step).
  ChosenWindow cut;
  if (cut_transient_)
    cut = cut_at_transient(StepSeries{{}, {}, {}, true, false}, series, window_from_s, now_s);
  const std::vector<double>& x = cut_transient_ ? cut.window : series;
  if (cut_transient_) window_from_s = cut.from_s;
  const WindowError w = window_error(x, window_from_s, now_s, true);
  const double rel = std::abs(w.err.covering_error / w.e.mean);
  last_rel_error_ = rel;
  const bool met = std::isfinite(rel) && rel < target_ && w.e.correlation_times >= kMinCorrelationTimes;
  if (!met) {
    met_since_s_ = -1.0;
    return false;
  }
  if (met_since_s_ < 0.0) met_since_s_ = now_s;
  // A stop the estimate itself decides comes where the estimate dipped (tau under-estimated): the
  // target must hold while a good part of the data changes, not only over a few correlation times.
  const double confirm_s = std::max(kConfirmCorrelationTimes * w.correlation_time_upper_s(),
                                    kConfirmWindowFraction * (met_since_s_ - window_from_s));
  return now_s - met_since_s_ >= confirm_s;
}

}  // namespace boycott::stats
