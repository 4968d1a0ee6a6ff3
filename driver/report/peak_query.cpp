#include "driver/report/peak_query.hpp"

#include <cmath>
#include <exception>
#include <map>
#include <set>
#include <utility>

#include <fmt/format.h>

#include "driver/store/store.hpp"
#include "driver/store/store_refine.hpp"
#include "driver/study/refine.hpp"
#include "stats/peak_refine.hpp"

namespace boycott::driver {
namespace {

/// [refine] of the study file as last run; none where it has none (or one this build refuses).
std::optional<RefinePlan> stored_plan(Database& db, const std::string& study) {
  const auto source = study_source(db, study);
  if (!source) return std::nullopt;
  try {
    return read_refine_plan(*source, study);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The curves of the points, in their order: runs of one group and setting.
std::vector<std::vector<const CurvePoint*>> curves_of(const std::vector<CurvePoint>& pts) {
  std::vector<std::vector<const CurvePoint*>> out;
  for (const auto& p : pts) {
    if (out.empty() || out.back().front()->group != p.group || out.back().front()->setting != p.setting)
      out.emplace_back();
    out.back().push_back(&p);
  }
  return out;
}

/// r_acc at the peak: its |<<w_p>>| over the curve's 90 deg point's, with the two errors
/// propagated to first order (independent: the 90 deg point is rarely among the three the
/// parabola takes).
void add_r_acc(const std::vector<const CurvePoint*>& curve, PeakRow& row) {
  for (const auto* p : curve) {
    if (p->angle_deg != 90.0 || p->w_m_s == 0.0 || !p->error.error_m_s) continue;
    const double w90 = std::abs(p->w_m_s), e90 = *p->error.error_m_s;
    const double y = row.peak.y, ey = row.peak.y_error();
    row.r_acc = y / w90;
    row.r_acc_err = *row.r_acc * std::hypot(ey / y, e90 / w90);
  }
}

PeakRow peak_row(const std::vector<const CurvePoint*>& curve, const std::optional<RefinePlan>& plan,
                 const std::set<std::string>& added_ids) {
  PeakRow row;
  row.group = curve.front()->group;
  row.setting = curve.front()->setting;
  const auto pts = peak_points(curve);
  row.points = static_cast<int>(pts.size());
  for (const auto* p : curve)
    for (const auto& id : p->replica_case_ids)
      if (added_ids.count(id)) {
        ++row.added;
        break;
      }
  if (plan) {
    row.objective = plan->objective;
    const auto step = stats::next_refinement(pts, row.added, {plan->resolution, plan->max_points});
    row.peak = step.peak.valid ? step.peak : stats::estimate_peak(pts);
    row.resolved = step.stop == stats::RefineStop::kResolved;
    row.status = step.stop == stats::RefineStop::kContinue ? "refining" : stats::to_string(step.stop);
    row.why = step.stop == stats::RefineStop::kContinue
                  ? fmt::format("the next point goes to {:g}: {}",
                                refined_value(step.next_x, plan->resolution), step.why)
                  : step.why;
  } else {
    row.peak = stats::estimate_peak(pts);
    const double reach = pts.empty() ? 0.0 : 0.5 * (pts.back().x - pts.front().x);
    row.resolved =
        row.peak.shape_checked && !row.peak.at_edge && stats::curvature_near(pts, row.peak.x, reach).peaked();
    row.status = "no_refine";
    row.why =
        "the study has no [refine]: resolved means inside the range, the points bending down, and more "
        "than the parabola's three points";
  }
  if (!row.peak.bracketed()) {
    row.resolved = false;
    row.status = stats::to_string(stats::RefineStop::kTooFewPoints);
    row.why = stats::too_few_points_why(pts.size()) +
              "; shown: the highest measured, its angle without an interval";
  }
  // Signed as the curve's largest value (settling is downward: negative).
  const CurvePoint* top = curve.front();
  for (const auto* p : curve)
    if (std::abs(p->w_m_s) > std::abs(top->w_m_s)) top = p;
  row.w_m_s = top->w_m_s < 0.0 ? -row.peak.y : row.peak.y;
  add_r_acc(curve, row);
  return row;
}

}  // namespace

std::vector<stats::PeakPoint> peak_points(const std::vector<const CurvePoint*>& curve) {
  std::vector<stats::PeakPoint> out;
  for (const auto* p : curve)
    if (p->error.error_m_s && *p->error.error_m_s > 0.0)
      out.push_back({p->angle_deg, std::abs(p->w_m_s), *p->error.error_m_s});
  return out;
}

std::vector<PeakRow> query_peak(Database& db, const std::string& study, const std::string& group) {
  const auto pts = query_curve(db, study, group);
  const auto plan = stored_plan(db, study);
  std::set<std::string> added_ids;
  for (const auto& r : refined_points(db, study)) added_ids.insert(r.case_id);
  std::vector<PeakRow> rows;
  for (const auto& curve : curves_of(pts)) {
    if (peak_points(curve).empty()) continue;
    rows.push_back(peak_row(curve, plan, added_ids));
  }
  return rows;
}

}  // namespace boycott::driver
