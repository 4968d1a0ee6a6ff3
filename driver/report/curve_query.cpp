#include "driver/report/curve_query.hpp"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <map>
#include <set>
#include <utility>

#include "driver/store/store.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

namespace {

// Group -> the replicas its adaptive plan starts with, from the study file as last run (a study
// file an older build stored and this one refuses: none, the plain between-replica rule).
std::map<std::string, int> adaptive_stage_one(Database& db, const std::string& study) {
  std::map<std::string, int> out;
  const std::optional<std::string> source = study_source(db, study);
  if (!source) return out;
  try {
    for (const auto& [grp, plan] : study_replica_plans(*source, study))
      if (plan.target_rel_error) out[grp] = plan.replicas;
  } catch (const std::exception&) {
  }
  return out;
}

/// One finished run of the study (or of one group) as a curve point of its own, with its first
/// position in the study file.
struct CurveRun {
  CurvePoint point;
  std::int64_t position = 0;
};

std::vector<CurveRun> curve_runs(Database& db, const std::string& study, const std::string& group) {
  std::vector<CurveRun> runs;
  for (auto& r : curve_results(db, study, group)) {
    CurvePoint p;
    p.group = std::move(r.group);
    p.case_id = std::move(r.case_id);
    p.angle_deg = r.angle_deg;
    p.w_m_s = r.w_m_s;
    p.w_err_m_s = r.w_err_m_s;
    p.error_method = std::move(r.error_method);
    p.run_dof = r.error_dof;
    p.n_particles = r.n_particles;
    p.average_from_s = r.average_from_s;
    p.end_s = r.end_s;
    runs.push_back({p, r.position});
  }
  return runs;
}

/// Each run's setting: what varies within its group at a given angle (a group's own `set` is its
/// name's job). A key zipped with the angle (each angle its own time.end, say) takes one value
/// per angle: it belongs to the angle's point, not to a second curve. Replicas differ in the seed
/// alone, which a study with replicas does not sweep: they share their setting and angle.
void name_settings(Database& db, std::vector<CurveRun>& runs) {
  std::vector<std::vector<SweptValue>> swept(runs.size());
  std::map<std::string, std::map<std::string, std::map<double, std::set<std::string>>>>
      values_at_angle;  // group -> key -> angle -> values
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const CurvePoint& p = runs[i].point;
    swept[i] = case_swept_values(db, p.case_id);
    for (const auto& v : swept[i]) values_at_angle[p.group][v.key][p.angle_deg].insert(v.value);
  }
  const auto splits_curve = [&](const std::string& grp, const std::string& key) {
    for (const auto& [angle, values] : values_at_angle[grp][key])
      if (values.size() >= 2) return true;
    return false;
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    CurvePoint& p = runs[i].point;
    for (const auto& v : swept[i]) {
      if (v.key == "gravity.angle_deg" || !splits_curve(p.group, v.key)) continue;
      p.setting += (p.setting.empty() ? "" : "; ") + v.key + "=" + v.display();
    }
  }
}

/// The runs in curve order: groups and settings in study order (the first position of any of
/// their cases), then by angle, replicas of one point adjacent and in study order.
std::vector<const CurveRun*> curve_order(const std::vector<CurveRun>& runs) {
  std::map<std::string, std::int64_t> group_pos;
  std::map<std::pair<std::string, std::string>, std::int64_t> first_pos;
  for (const auto& r : runs) {
    auto& gp = group_pos.try_emplace(r.point.group, r.position).first->second;
    gp = std::min(gp, r.position);
    auto& fp = first_pos.try_emplace({r.point.group, r.point.setting}, r.position).first->second;
    fp = std::min(fp, r.position);
  }
  std::vector<const CurveRun*> order;
  for (const auto& r : runs) order.push_back(&r);
  std::stable_sort(order.begin(), order.end(), [&](const CurveRun* x, const CurveRun* y) {
    const CurvePoint &a = x->point, &b = y->point;
    if (a.group != b.group) return group_pos[a.group] < group_pos[b.group];
    if (a.setting != b.setting) return first_pos[{a.group, a.setting}] < first_pos[{b.group, b.setting}];
    if (a.angle_deg != b.angle_deg) return a.angle_deg < b.angle_deg;
    return x->position < y->position;  // replicas in study order
  });
  return order;
}

/// One point from its replicas (one or more runs of the same group, setting and angle): their
/// mean, and the error as stats/point_error.hpp explains (stage_one: the replicas an adaptive
/// group starts with, 0 for a fixed count).
CurvePoint point_of_replicas(const std::vector<const CurveRun*>& replicas, int stage_one) {
  const CurvePoint& first = replicas.front()->point;
  CurvePoint p = first;
  p.n_replicas = static_cast<int>(replicas.size());
  double err_sum = 0.0;
  bool all_errors = true;
  std::vector<stats::RunEstimate> runs;
  for (const CurveRun* run : replicas) {
    const CurvePoint& r = run->point;
    p.replica_case_ids.push_back(r.case_id);
    p.replica_w_m_s.push_back(r.w_m_s);
    if (r.w_err_m_s)
      err_sum += *r.w_err_m_s;
    else
      all_errors = false;
    if (r.error_method != p.error_method) p.error_method = "mixed";
    runs.push_back({r.w_m_s, r.w_err_m_s, r.run_dof});
  }
  const stats::ReplicaMean mean = stats::replica_mean(p.replica_w_m_s);
  p.w_m_s = mean.mean;
  p.error = stats::point_error(runs, stage_one);
  if (all_errors)
    p.mean_within_run_stderr_m_s =
        p.n_replicas == 1 ? *first.w_err_m_s : err_sum / static_cast<double>(p.n_replicas);
  if (mean.between_stderr) {
    p.between_replica_stderr_m_s = mean.between_stderr;
    p.w_err_m_s = p.between_replica_stderr_m_s;
  }
  return p;
}

/// r_acc = w / w90 with its covering error from the two points' (stats/point_error.hpp).
void add_acceleration_ratios(std::vector<CurvePoint>& pts) {
  for (auto& p : pts) {
    const CurvePoint* ref = nullptr;
    for (const auto& q : pts)
      if (q.group == p.group && q.setting == p.setting && q.angle_deg == 90.0) ref = &q;
    if (!ref || ref->w_m_s == 0.0) continue;
    p.r_acc = p.w_m_s / ref->w_m_s;
    // At 90 deg itself the ratio is exactly 1 (the same number over itself).
    p.r_acc_err = &p == ref || p.case_id == ref->case_id
                      ? 0.0
                      : stats::ratio_error(p.w_m_s, p.error, ref->w_m_s, ref->error);
  }
}

}  // namespace

std::vector<CurvePoint> query_curve(Database& db, const std::string& study, const std::string& group) {
  std::vector<CurveRun> runs = curve_runs(db, study, group);
  name_settings(db, runs);
  const std::vector<const CurveRun*> order = curve_order(runs);
  const std::map<std::string, int> stage_one = adaptive_stage_one(db, study);
  // Replicas of one point (adjacent now) become one point.
  std::vector<CurvePoint> pts;
  for (std::size_t k = 0; k < order.size();) {
    const CurvePoint& first = order[k]->point;
    std::size_t end = k;
    while (end < order.size() && order[end]->point.group == first.group &&
           order[end]->point.setting == first.setting && order[end]->point.angle_deg == first.angle_deg)
      ++end;
    const auto stage = stage_one.find(first.group);
    pts.push_back(point_of_replicas(
        {order.begin() + static_cast<std::ptrdiff_t>(k), order.begin() + static_cast<std::ptrdiff_t>(end)},
        stage == stage_one.end() ? 0 : stage->second));
    k = end;
  }
  add_acceleration_ratios(pts);
  return pts;
}

}  // namespace boycott::driver
