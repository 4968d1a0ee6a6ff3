#pragma once
// `query peak`: where each curve of a study peaks and how well that is known (stats/peak_fit.hpp:
// the parabola through the highest point and its neighbours, Monte Carlo over the points' covering
// errors, the model's own error), with r_acc at the peak, the points it rests on and whether it is
// resolved: inside the sampled range and known to the study's [refine] resolution. The curves are
// query_curve's (replicas averaged); a curve peaks where |<<w_p>>| does, which is where r_acc does
// (one curve divided by one number). peak.hpp shows the rows.
#include <optional>
#include <string>
#include <vector>

#include "driver/report/curve_query.hpp"
#include "driver/store/database.hpp"
#include "stats/peak_fit.hpp"

namespace boycott::driver {

/// A curve's points as the peak fit takes them: |<<w_p>>| against the angle with the covering
/// error; points without an error are left out (the fit weighs by errors).
std::vector<stats::PeakPoint> peak_points(const std::vector<const CurvePoint*>& curve);

/// The peak of one curve (a group and setting of query_curve).
struct PeakRow {
  std::string group, setting;
  std::string objective;                   ///< [refine]'s objective, "" without [refine]
  stats::PeakEstimate peak;                ///< abscissa: the angle (deg); value: |<<w_p>>| (m/s)
  double w_m_s = 0.0;                      ///< <<w_p>> at the peak, signed as the curve's
  std::optional<double> r_acc, r_acc_err;  ///< over the curve's 90 deg point; unset without one
  int points = 0;                          ///< the curve's points with an error
  int added = 0;                           ///< of them, added by [refine]
  bool resolved = false;  ///< inside the sampled range, known to the resolution, bending down
  std::string status;     ///< stats::to_string(RefineStop), or "no_refine"
  std::string why;        ///< the refinement rule's words
};

/// Per curve of the study (of one group, `group` non-empty), in curve order.
std::vector<PeakRow> query_peak(Database& db, const std::string& study, const std::string& group = "");

}  // namespace boycott::driver
