#pragma once
// time.target_rel_error's rule: when a run's time average is known well enough to stop.
#include <cstdint>
#include <limits>
#include <vector>

namespace boycott::stats {

/// time.target_rel_error: a run may stop once Sokal's covering error of <<w_p>> over its window
/// (AutocorrelationError::covering_error; the error_m_s of a run it stops) is below
/// target |<<w_p>>|, the window holds at least kMinCorrelationTimes correlation times
/// (counted conservatively, AutocorrelationError::correlation_times), and the target has been
/// met at every check over at least kConfirmCorrelationTimes correlation times and over
/// kConfirmWindowFraction of the window it was first met at (two checks that far apart, none
/// failing between). Confirming over 10 correlation times alone let the error at the stop cover
/// 0.65 (the stop came where tau was under-estimated); over 30 % of the window it covers
/// 0.665-0.677 at five targets where the target decides the stop, and 0.658-0.659 where the
/// floor of kMinCorrelationTimes does (10 000 series each), for runs ~25 % longer
/// (docs/validation.md, "Error bars"). Not batch means, which a run that ends at time.end
/// reports: their few degrees of freedom at these lengths make the error noisy, the stop comes
/// where it dipped, and it then covers 0.62 (0.65 if Sokal's judges the stop and batch means are
/// reported). Checks fall on a fixed schedule of sample counts, so a resumed run checks where the
/// uninterrupted one did; the state goes into checkpoints.
class PrecisionTarget {
 public:
  static constexpr double kMinCorrelationTimes = 50.0;
  static constexpr double kConfirmCorrelationTimes = 10.0;
  static constexpr double kConfirmWindowFraction = 0.3;
  static constexpr std::int64_t kFirstCheck = 50;  ///< samples

  /// target: time.target_rel_error (NaN: no target, never stops). cut_transient: the window is
  /// the run's own choice (time.average_from = "auto"): each check judges the series from where
  /// its start-up transient is detected to end.
  explicit PrecisionTarget(double target, bool cut_transient = false)
      : target_(target), cut_transient_(cut_transient) {}
  bool active() const { return target_ == target_; }
  /// After a sample was added to `series`: true when the run may stop now.
  bool reached(const std::vector<double>& series, double window_from_s, double now_s);
  /// The last check's relative error (NaN before the first).
  double last_rel_error() const { return last_rel_error_; }

  // State, for checkpoints.
  std::int64_t next_check_ = kFirstCheck;
  double met_since_s_ = -1.0;  ///< time of the first check of the streak; < 0: not met

 private:
  double target_;
  bool cut_transient_;
  double last_rel_error_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace boycott::stats
