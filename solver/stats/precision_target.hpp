#pragma once
// time.target_rel_error's rule: when a run's time average is known well enough to stop.
#include <cstdint>
#include <limits>
#include <vector>

#include "stats/window_error.hpp"

namespace boycott::stats {

/// time.target_rel_error by Stein's two-stage rule (C. Stein, Ann. Math. Stat. 16, 243 (1945)),
/// the rule adaptive replicas follow (stats/point_error.hpp): the stop is planned once, not judged
/// at every check.
/// - The first check at which the window holds kMinCorrelationTimes correlation times (counted
///   conservatively, AutocorrelationError::correlation_times; spans where tau_int has no estimate)
///   fixes the first stage: kFirstStageFactor
///   times as many samples.
/// - At the first stage (n0 samples) the window's batch means (mean_error, at most
///   kFirstStageMaxBatches) give a standard error se0 at dof0 degrees of freedom; the run is
///   planned to stop at max(n0, n0 (t_dof0 se0 / (target |mean|))^2) samples, and stops there
///   (TwoStagePlan).
/// - It then reports se0 sqrt(n0 / n) times t at dof0 (two_stage_error), below the target by
///   construction. The length depends on se0 alone, so the mean over it scatters as if the
///   length had been fixed in advance, and t at dof0 covers it if se0 is unbiased.
///
/// Why at most 4 batches at the first stage: the whole plan rests on se0, and batches of a first
/// stage of ~200 counted correlation times are, with 8 of them, only a few times the slow part's
/// time on sums of AR(1) processes 3-30 apart (whose tau_int a slow part of small weight hardly
/// moves): neighbours correlate and se0 comes out low (coverage 0.633 at the stop over 2 000
/// such series; 4 batches: 0.673; docs/validation.md, "Series that are not AR(1)"). The price: t_3 instead of
/// t_7, a run ~20 % longer where the target decides the stop.
///
/// Why not stop when the error first meets the
/// target, confirmed over a while (the earlier rule): the stop then comes where the estimate dipped; with
/// Sokal's error, which a slow part of the series biases low, it covered 0.57-0.60 on sums of AR(1)
/// processes; with batch means, whose few degrees of freedom make them noisy, 0.62 on AR(1). Why the first
/// stage lies well past the first count of 50: the count is itself an estimate, and the runs that reach it
/// first are those whose tau_int was estimated low; four times as far, three quarters of the first stage's
/// data were not yet seen when it was fixed.
///
/// Checks fall on a fixed schedule of sample counts, so a resumed
/// run checks where the uninterrupted one did; the state goes into checkpoints.
class PrecisionTarget {
 public:
  static constexpr double kMinCorrelationTimes = 50.0;
  static constexpr double kFirstStageFactor = 4.0;
  static constexpr int kFirstStageMaxBatches = 4;
  static constexpr std::int64_t kFirstCheck = 50;  ///< samples

  /// target: time.target_rel_error (NaN: no target, never stops). cut_transient: the window is
  /// the run's own choice (time.average_from = "auto"): the first stage cuts it where its start-up
  /// transient is detected to end, and the cut stays.
  explicit PrecisionTarget(double target, bool cut_transient = false)
      : target_(target), cut_transient_(cut_transient) {}
  bool active() const { return target_ == target_; }
  /// After a sample was added to `series` (every sample since the window's collection began, at
  /// window_from_s): true when the run may stop now.
  bool reached(const std::vector<double>& series, double window_from_s, double now_s);
  /// The relative error the plan stops at, or the last check's before it (NaN before the first).
  double last_rel_error() const { return last_rel_error_; }
  /// The plan, once its first stage is done (for the summary of a run it stopped).
  const TwoStagePlan& plan() const { return plan_; }

  // State, for checkpoints (to_state / from_state).
  std::int64_t next_check_ = kFirstCheck;
  std::int64_t first_stage_at_ = 0;  ///< samples; 0: not yet fixed
  TwoStagePlan plan_;
  /// The state as numbers, and back (a vector of 2, from builds before the plan: no plan yet).
  std::vector<double> to_state() const;
  void from_state(const std::vector<double>& v);

 private:
  /// plan_.planned and last_rel_error_ from the first stage in plan_ and target_.
  void plan_length();
  /// The first stage's covering error relative to its mean, t_dof0 se0 / |mean0|.
  double se0_rel_covering() const;
  double target_;
  bool cut_transient_;
  double last_rel_error_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace boycott::stats
