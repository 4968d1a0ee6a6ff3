#pragma once
// `query curve`'s points: the correlation curve <<w_p>>(theta) and r_acc(theta) of a study's
// finished cases, read through the store, the replicas of a point averaged with their error
// (stats/point_error.hpp). curve.hpp shows them.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driver/store/database.hpp"
#include "stats/point_error.hpp"

namespace boycott::driver {

/// One point of a curve: a (group, setting, angle) and its finished replicas (the cases of the
/// study that differ only in their seed; one without `replicas`).
struct CurvePoint {
  std::string group;
  /// What else the study sets on the case besides the angle ("key=value; ..."), empty when the
  /// group sweeps only the angle: one curve per (group, setting), r_acc within it.
  std::string setting;
  std::string case_id;  ///< the first replica's
  double angle_deg = 0;
  double w_m_s = 0;  ///< <<w_p>>, the mean over the replicas
  /// The standard error of w_m_s: between_replica_stderr_m_s with two replicas or more, else the
  /// run's own error; unset when the run recorded none.
  std::optional<double> w_err_m_s;
  int n_replicas = 1;
  std::vector<std::string> replica_case_ids;
  std::vector<double> replica_w_m_s;  ///< each replica's <<w_p>>, in study order
  /// Sample standard deviation of the replicas' <<w_p>> over sqrt(N); unset below two replicas.
  std::optional<double> between_replica_stderr_m_s;
  /// The mean of the replicas' own (within-run) errors; unset when any replica recorded none.
  std::optional<double> mean_within_run_stderr_m_s;
  /// How the runs estimated their own errors (summary.json's settling_velocity_error_method;
  /// "batch_means" for runs that predate it), "mixed" when the replicas differ.
  std::string error_method;
  /// The covering error of w_m_s (error_m_s, about 68 % for any number of replicas) and what it
  /// rests on (error_basis); stats/point_error.hpp.
  stats::PointError error;
  /// A single run's degrees of freedom of its error (summary.json settling_velocity_error_dof).
  std::optional<double> run_dof;
  /// <<w_p>>/<<w_p>>(90 deg), unset without a 90 deg case; its covering error, from the two
  /// points' errors, unset when an error it depends on is.
  std::optional<double> r_acc, r_acc_err;
  /// The first replica's particle count and averaging window [average_from_s, end_s] (s), as
  /// case_id is the first replica's; unset where its summary or the case did not say.
  std::optional<std::int64_t> n_particles;
  std::optional<double> average_from_s, end_s;
};

/// The correlation curve of finished cases, per group in study order, by angle; the replicas of
/// a point (cases that differ only in their seed) are averaged, r_acc's error propagated from
/// their scatter.
std::vector<CurvePoint> query_curve(Database& db, const std::string& study, const std::string& group = "");

}  // namespace boycott::driver
