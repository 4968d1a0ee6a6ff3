#pragma once
// The error bar of a curve point and of r_acc: a half-width that covers the true value about 68 %
// of the time (stats/distributions.hpp: kOneSigmaCoverage) however few numbers it rests on.
//
// - One run: its own covering error (summary.json settling_velocity_error_m_s: its standard error,
//   from the autocorrelation or from the window's two halves, times Student's t at that estimate's
//   degrees of freedom; stats/window_error.hpp, MeanError).
// - n >= 2 replicas: t_{n-1} s / sqrt(n) (s: the replicas' sample standard deviation); where every
//   replica states its own error, an F test of the scatter against those errors (which are
//   themselves estimates, with their own degrees of freedom): when the two disagree (two-sided,
//   5 %), the larger of the between-replica and the pooled within-run error is shown and the basis
//   says so.
// - Adaptive replicas (replicas_target_rel_error): Stein's two-stage rule (C. Stein, Ann. Math.
//   Stat. 16, 243 (1945)): the first n0 replicas' s0 fixes how many replicas the point needs, n,
//   and the error is t_{n0-1} s0 / sqrt(n), which covers exactly whatever n s0 led to; the plain
//   t_{n-1} s / sqrt(n) after a stop that s itself decided covers less (0.63 at a target that needs
//   8 replicas).
// - r_acc = w / w90: first-order propagation of the two points' variances with Welch's (1947)
//   degrees of freedom, then Student's t at those (welch_dof below).
#include <optional>
#include <string>
#include <vector>

namespace boycott::stats {

/// One run's <<w_p>> and its error, as the database holds it.
struct RunEstimate {
  double w_m_s = 0.0;
  std::optional<double> stderr_m_s;  ///< plain standard error (settling_velocity_stderr_m_s)
  std::optional<double> dof;         ///< its degrees of freedom (settling_velocity_error_dof)
};

/// A point's covering error and what it rests on.
struct PointError {
  std::optional<double> error_m_s;  ///< half-width covering ~68 %; unset: none available
  /// between_replicas_t, two_stage_stein, within_runs_pooled, single_run, or for runs of builds
  /// that recorded no degrees of freedom single_run_plain (the plain standard error); with
  /// "; ..." when the replicas' scatter and their own errors disagree.
  std::string basis;
  /// The plain standard error and its degrees of freedom (for r_acc's propagation).
  std::optional<double> plain_m_s;
  double dof = 0.0;
};

/// The replicas' mean and, from two replicas on, the standard error of that mean from their
/// scatter, s / sqrt(n) (s: their sample standard deviation); one replica: its own value.
struct ReplicaMean {
  double mean = 0.0;
  std::optional<double> between_stderr;  ///< unset below two replicas
};
/// `w`: each replica's value, in study order (at least one).
ReplicaMean replica_mean(const std::vector<double>& w);

/// The covering error of the mean of `runs` (replicas of one point, in study order).
/// `stage_one`: the replicas an adaptive plan starts with (0: not adaptive). At least 2 is
/// needed for Stein's rule; with fewer runs than that the plain between-replica rule applies.
PointError point_error(const std::vector<RunEstimate>& runs, int stage_one = 0);

/// The covering error of r = w / w90 from the two points' plain errors and degrees of freedom
/// (independent points; welch_dof). Unset when either has none.
std::optional<double> ratio_error(double w, const PointError& e, double w90, const PointError& e90);

/// The degrees of freedom of a sum of two independent variance estimates var_a + var_b with dof_a
/// and dof_b (infinite: known): B. L. Welch, Biometrika 34, 28 (1947),
/// (var_a + var_b)^2 / (var_a^2 / (dof_a + 2) + var_b^2 / (dof_b + 2)) - 2, at least
/// min(dof_a, dof_b). Satterthwaite's form (dof_i in place of dof_i + 2, no - 2) estimates each
/// sigma^4 by s^4, which is biased high by (nu + 2) / nu: 3x at one degree of freedom, so its
/// count is low where the parts rest on 1-2 each, and t at it covers 0.70-0.74 at 2 replicas per
/// point. Welch's covers 0.665-0.70 there, 0.67-0.69 at 3 and 4 (docs/validation.md, "r_acc").
double welch_dof(double var_a, double dof_a, double var_b, double dof_b);

/// The replicas an adaptive point needs under Stein's rule: the smallest n >= stage-one count
/// with t_{n0-1} s0 / sqrt(n) <= target |mean0|, at most `max` (from its first replicas).
int stein_replicas_needed(const std::vector<double>& stage_one_w, double target_rel_error, int max);

}  // namespace boycott::stats
