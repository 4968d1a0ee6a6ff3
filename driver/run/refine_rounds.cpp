#include "driver/run/refine_rounds.hpp"

#include <algorithm>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/report/peak_query.hpp"
#include "driver/store/store.hpp"
#include "driver/store/store_refine.hpp"
#include "driver/study/refine.hpp"
#include "stats/peak_refine.hpp"

namespace boycott::driver {
namespace {

std::string curve_name(const RefineSeries& c) {
  return c.setting.empty() ? fmt::format("group {}", c.group)
                           : fmt::format("group {} ({})", c.group, c.setting);
}

/// The point and its replicas (replica k with seed + k), as the group's plan starts every point.
std::vector<StudyCase> with_replicas(const Study& s, const StudyCase& point) {
  std::vector<StudyCase> out{point};
  const auto plan = s.replica_plans.find(point.group);
  const int n = plan == s.replica_plans.end() ? 1 : plan->second.replicas;
  for (int k = 1; k < n; ++k) out.push_back(replica_of(point, k));
  return out;
}

const RefineSeries* find_curve(const std::vector<RefineSeries>& curves, const std::string& group,
                               const std::string& setting) {
  for (const auto& c : curves)
    if (c.group == group && c.setting == setting) return &c;
  return nullptr;
}

/// Whether every case of the curve has finished: done, or failed for good.
bool finished(const RefineSeries& curve, const std::map<std::string, CaseStatus>& status) {
  return std::all_of(curve.cases.begin(), curve.cases.end(), [&](const StudyCase* c) {
    const auto it = status.find(c->id);
    return it != status.end() && (it->second == CaseStatus::kDone || it->second == CaseStatus::kFailed);
  });
}

/// The curve's points as query_curve makes them (replicas averaged), of its own cases only.
std::vector<stats::PeakPoint> curve_points(const RefineSeries& curve,
                                           const std::vector<CurvePoint>& group_pts) {
  std::vector<const CurvePoint*> mine;
  for (const auto& p : group_pts)
    if (std::any_of(curve.cases.begin(), curve.cases.end(),
                    [&](const StudyCase* c) { return c->id == p.case_id; }))
      mine.push_back(&p);
  return peak_points(mine);
}

}  // namespace

void add_recorded_refinements(Database& db, Study& s) {
  if (!s.refine) return;
  const auto rows = refined_points(db, s.name);
  if (rows.empty()) return;
  const auto curves = refine_series(s);  // of the listed cases: the points below join them
  std::vector<StudyCase> added;
  for (const auto& r : rows) {
    const RefineSeries* curve = find_curve(curves, r.group, r.setting);
    if (!curve) {
      std::fprintf(
          stderr,
          "refine: the database's point %s = %g of group %s%s is of no curve of the study now; left out\n",
          r.key.c_str(), r.value, r.group.c_str(), r.setting.empty() ? "" : (" (" + r.setting + ")").c_str());
      continue;
    }
    const StudyCase c = refined_case(s, *curve, r.value, r.round);
    if (c.id != r.case_id)
      std::fprintf(
          stderr,
          "refine: %s round %d (%s = %g) is case %s now, not the recorded %s: the study's [refine] set "
          "or its cases changed\n",
          curve_name(*curve).c_str(), r.round, r.key.c_str(), r.value, c.id.c_str(), r.case_id.c_str());
    for (auto& rc : with_replicas(s, c)) added.push_back(std::move(rc));
  }
  s.cases.insert(s.cases.end(), added.begin(), added.end());
}

RefineRound next_refine_round(Database& db, const Study& s, int retries) {
  RefineRound round;
  if (!s.refine) return round;
  const RefinePlan& plan = *s.refine;
  std::map<std::string, CaseStatus> status;
  for (const auto& st : case_states(db, s.name, retries)) status[st.id] = st.status;
  std::map<std::string, std::vector<CurvePoint>> by_group;
  for (const auto& curve : refine_series(s)) {
    if (!finished(curve, status)) {
      ++round.waiting;
      continue;
    }
    if (!by_group.count(curve.group)) by_group[curve.group] = query_curve(db, s.name, curve.group);
    const auto pts = curve_points(curve, by_group[curve.group]);
    const int added =
        static_cast<int>(std::count_if(curve.cases.begin(), curve.cases.end(), [](const StudyCase* c) {
          return c->refine_round >= 0 && c->replica == 0;
        }));
    const auto step = stats::next_refinement(pts, added, {plan.resolution, plan.max_points});
    if (step.stop != stats::RefineStop::kContinue) {
      round.stopped.push_back(
          fmt::format("{}: {}: {}", curve_name(curve), stats::to_string(step.stop), step.why));
      continue;
    }
    const double value = refined_value(step.next_x, plan.resolution);
    RefinedPoint row{s.name, curve.group, curve.setting, added, "", plan.key, value, step.why, ""};
    StudyCase c = refined_case(s, curve, value, added);
    row.case_id = c.id;
    const RefinedPoint stored = record_refined_point(db, row, c);
    if (stored.case_id != c.id) c = refined_case(s, curve, stored.value, added);  // another driver's choice
    round.adding.push_back(fmt::format("{}: round {} adds {} = {:g} ({})", curve_name(curve), added + 1,
                                       plan.key, stored.value, stored.reason));
    for (auto& rc : with_replicas(s, c)) round.added.push_back(std::move(rc));
  }
  return round;
}

void print_refine_round(const RefineRound& round, std::set<std::string>& told) {
  for (const auto& line : round.stopped)
    if (told.insert(line).second) std::fprintf(stderr, "refine: %s\n", line.c_str());
  for (const auto& line : round.adding) std::fprintf(stderr, "refine: %s\n", line.c_str());
}

}  // namespace boycott::driver
