#pragma once
// Error against run time: a work-precision study has one group of fine
// reference runs (default name "reference") and groups that each change one setting (time.dt_dem,
// domain.cells, ...), all over the same gravity.angle_deg values. Every finished point outside the
// reference group is compared with the reference point of its angle. A point is a (group,
// setting, angle) with its finished replicas (`replicas` in the study): their mean, the standard
// error of that mean (their scatter; one run's own error without replicas) and the mean cost of
// one of its runs, as the curve has them (driver/report/curve_query.hpp, CurvePoint); the errors of
// the differences are the statistics room's (stats/relative_difference.hpp).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driver/report/curve.hpp"
#include "driver/report/plot_cairo.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"

namespace boycott::driver {

struct WorkPrecisionRow {
  std::string group, case_id;
  std::vector<SweptValue> setting;  ///< the case's swept values without gravity.angle_deg
  double angle_deg = 0;
  std::optional<double> wall_time_s;
  std::optional<std::int64_t> particle_steps;  ///< with wall_time_s: one run's, the mean over replicas
  double w_m_s = 0, w_err_m_s = 0;             ///< <<w_p>> and its standard error
  int n_replicas = 1;                          ///< the runs averaged; case_id is the first one's
  std::string ref_case_id;
  double w_ref_m_s = 0, w_ref_err_m_s = 0;
  int ref_n_replicas = 1;
  /// w / w_ref - 1: positive when the case settles faster than the reference (both velocities
  /// have the sign of gravity, so this is (|w| - |w_ref|)/|w_ref| whenever w and w_ref agree in sign).
  double rel_error_w = 0;
  double rel_error_w_unc = 0;  ///< first-order propagation of both standard errors, independent
  /// The half-width that covers the true rel_error_w ~68 % of the time: the points' plain errors
  /// propagated, times Student's t at Welch's degrees of freedom of the two (stats::ratio_error,
  /// as r_acc's). Unset where either point has no error of its own.
  std::optional<double> rel_error_w_err;
  /// r_acc(theta) / r_acc_ref(theta) - 1, r_acc = w(theta)/w(90) within the same group and
  /// setting; unset at 90 deg and where the group has no 90 deg case of the same setting.
  std::optional<double> rel_error_r_acc, rel_error_r_acc_unc;
};

struct ReferenceRun {
  std::string case_id;
  double angle_deg = 0;
  double w_m_s = 0, w_err_m_s = 0;
  std::optional<double> wall_time_s;
  int n_replicas = 1;
};

struct WorkPrecision {
  std::string study, reference_group;
  std::vector<ReferenceRun> references;  ///< the finished reference cases used, by angle
  std::vector<WorkPrecisionRow> rows;    ///< groups in study order, by wall time within a group
};

/// InputError when the study or the reference group does not exist, when a case has no finished
/// reference case at its angle (naming the group and the angle), when the reference group has
/// cases of several settings at one angle (naming them; replicas of one setting are averaged), or
/// when a reference <<w_p>> is zero.
WorkPrecision query_work_precision(Database& db, const std::string& study,
                                   const std::string& reference_group = "reference");

std::string format_work_precision(const WorkPrecision& wp, ListingFormat f);

/// rel_error_w in % (signed, linear, the reference at 0) against wall time (log), one panel per
/// angle: one colour and marker per group, its points joined in the order of the varied setting
/// and labelled with its key and value in the key's unit ("dt_dem 50 µs"), labels moved apart
/// where they would overlap, covering error bars (rel_error_w_err) clipped to the frame, the
/// reference's wall time as a dashed vertical line. A bar that crosses 0 is a setting that cannot
/// be told from the reference. Drawn with Cairo as SVG, PDF or PNG (driver/report/plot_cairo.hpp).
plot::Plot work_precision_plot(const WorkPrecision& wp, const std::string& title,
                               plot::Format format = plot::Format::kSvg);

}  // namespace boycott::driver
