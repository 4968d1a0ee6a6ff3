#include "driver/run/plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "checks/preflight.hpp"
#include "core/error.hpp"
#include "core/scene_specs.hpp"
#include "driver/report/listing_format.hpp"
#include "driver/report/report_util.hpp"
#include "driver/run/progress.hpp"
#include "driver/run/refine_rounds.hpp"
#include "driver/run/run_tree.hpp"
#include "driver/run/runner.hpp"
#include "driver/store/store.hpp"
#include "driver/study/cost_model.hpp"
#include "driver/study/refine.hpp"
#include "stats/peak_fit.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {

namespace {
std::string duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  if (s >= 48 * 3600.0) return fmt::format("{:.1f} d", s / 86400.0);
  if (s >= 3600.0) return fmt::format("{:.1f} h", s / 3600.0);
  if (s >= 60.0) return fmt::format("{:.1f} min", s / 60.0);
  return fmt::format("{:.0f} s", s);
}

std::vector<MeasuredCost> measured(Database& db) {
  std::vector<MeasuredCost> out;
  for (const auto& f : finished_costs(db)) {
    bool ok = false;
    auto m = measured_cost(f.case_id, f.params_json, f.summary_json, &ok);
    if (ok) out.push_back(std::move(m));
  }
  return out;
}

CaseWork work_of(const StudyCase& c, double from_s = 0.0) {
  return case_work(to_json(c.params), from_s, c.params.time.end_s);
}

/// The simulated time a case's run folder has reached (its time series' last row), s; 0 where
/// it has none, and for a scene that keeps no checkpoints (it does not read
/// time.checkpoint_every), whose rerun starts over. An interrupted case resumes from its last
/// checkpoint, at most an output interval or a checkpoint interval before this.
double reached_s(const fs::path& runs_root, const StudyCase& c) {
  if (runs_root.empty() || !scene_reads(scene_spec(c.params.scene), "time.checkpoint_every")) return 0.0;
  return std::clamp(simulated_time_s(runs_root / c.id), 0.0, c.params.time.end_s);
}

/// What a case has left to run: from where its run folder stands, at the fluid step its run
/// takes now (its last row's dt_s) where the CFL limit or the packed-bed limit
/// (numerics.drag_dt_limit) has cut time.dt_cfd: a 10 cP bed packs and steps at 0.13-0.3 ms
/// where dt_cfd is 1 ms, so its rest costs several times the planned steps'. The DEM step is
/// not cut; the fluid's cost per cell-step is taken as the model's.
/// Where the packed-bed limit is on and a packed bed's stable step (checks::packed_bed_stable_dt_s)
/// lies below the step the rest is costed at, the same rest at that step is its upper end: the
/// step falls towards it as a bed packs (the inclined 10 cP points from 1 ms to 0.3 ms within
/// their first 1.3 s), and stays where no bed forms.
struct Rest {
  double reached_s = 0.0;
  double fluid_step_s = 0.0;  ///< the step the rest is costed at, s
  CaseWork work;
  double packed_step_s = 0.0;  ///< > 0: the packed bed's stable step, below fluid_step_s
  CaseWork packed_work;        ///< the rest at packed_step_s
  /// The rest at its upper end: at the packed bed's step where there is one.
  const CaseWork& upper_work() const { return packed_step_s > 0.0 ? packed_work : work; }
};
Rest rest_of(const fs::path& runs_root, const StudyCase& c) {
  Rest r;
  r.reached_s = reached_s(runs_root, c);
  r.work = work_of(c, r.reached_s);
  r.fluid_step_s = c.params.time.dt_cfd_s;
  const double now_s = r.reached_s > 0.0 ? last_row_value(runs_root / c.id, "dt_s") : 0.0;
  if (now_s > 0.0 && now_s < r.fluid_step_s) {
    r.work.fluid_cell_steps *= r.fluid_step_s / now_s;
    r.fluid_step_s = now_s;
  }
  const double packed_s = c.params.numerics.drag_dt_limit ? checks::packed_bed_stable_dt_s(c.params) : 0.0;
  if (packed_s > 0.0 && packed_s < r.fluid_step_s && r.work.fluid_cell_steps > 0.0) {
    r.packed_step_s = packed_s;
    r.packed_work = r.work;
    r.packed_work.fluid_cell_steps *= r.fluid_step_s / packed_s;
  }
  return r;
}

std::string swept_text(const StudyCase& c) {
  std::string s;
  for (const auto& [k, v] : c.swept) s += (s.empty() ? "" : " ") + k + "=" + readable_value(v);
  if (c.replica > 0) s += fmt::format("{}replica {}", s.empty() ? "" : " ", c.replica);
  return s.empty() ? "-" : s;
}
}  // namespace

PlanEstimate plan_estimate(Database& db, const Study& study, const std::vector<std::string>& to_run_ids,
                           int jobs, int ranks, const fs::path& runs_root) {
  const CostModel model(measured(db));
  std::map<std::string, const StudyCase*> by_id;
  for (const auto& c : study.cases) by_id[c.id] = &c;
  std::vector<double> costs, packed;
  std::map<std::string, PlannedCase> planned;
  std::map<std::string, bool> scenes;
  for (const auto& id : to_run_ids)
    if (const auto it = by_id.find(id); it != by_id.end()) {
      const Rest rest = rest_of(runs_root, *it->second);
      costs.push_back(model.core_s(rest.work));
      packed.push_back(model.core_s(rest.upper_work()));
      planned[id] =
          PlannedCase{study_wall_s({costs.back()}, 1, ranks), rest.reached_s, it->second->params.time.end_s};
      scenes[it->second->params.scene] = true;
    }
  std::string basis;
  for (const auto& [scene, _] : scenes)
    basis += (basis.empty() ? "" : ", ") + scene + ": " + model.basis(scene);
  const double wall = study_wall_s(costs, jobs, ranks), wall_packed = study_wall_s(packed, jobs, ranks);
  PlanEstimate e;
  e.line = fmt::format("plan: {} to run, estimated {}{} on {} x {} (cost model {})",
                       count_of(static_cast<long long>(costs.size()), "case"), duration(wall),
                       wall_packed > wall ? fmt::format(" (up to {} should packed beds cut the fluid step)",
                                                        duration(wall_packed))
                                          : std::string(),
                       count_of(jobs, "job"), count_of(ranks, "rank"), basis.empty() ? "-" : basis);
  e.cases = std::move(planned);
  return e;
}

namespace {

/// Every case of the plan: its JSON row (numbers in seconds) and its line in the table.
struct PlanRows {
  nlohmann::json rows = nlohmann::json::array();
  report::TextTable table;
  std::vector<double> pending_costs;        ///< core-seconds of each case still to run
  std::vector<double> pending_costs_upper;  ///< the same, each at its packed bed's step where lower
  double total_core_s = 0.0;                ///< of every case, done or not
};

PlanRows plan_rows(const Study& study, const PlanOptions& opt, const std::map<std::string, CaseState>& states,
                   const std::vector<MeasuredCost>& finished, const CostModel& model) {
  std::map<std::string, const MeasuredCost*> measured_by_id;
  for (const auto& m : finished) measured_by_id[m.case_id] = &m;
  std::vector<std::string> header{"group", "varied", "case", "state", "core time"};
  if (opt.check_model) header.emplace_back("leave one out");
  PlanRows out{nlohmann::json::array(),
               report::TextTable(header, {false, false, false, false, true, false}),
               {},
               {},
               0.0};
  const fs::path root = opt.db_path.empty() ? fs::path() : fs::path(runs_root(opt.db_path));
  for (const auto& c : study.cases) {
    const auto it = states.find(c.id);
    const CaseStatus st = it == states.end() ? CaseStatus::kPending : it->second.status;
    const double est = model.core_s(work_of(c));
    out.total_core_s += est;
    // A case that has run part of its time needs only the rest.
    const Rest rest = st == CaseStatus::kDone ? Rest{} : rest_of(root, c);
    const double reached = rest.reached_s;
    const double left = st == CaseStatus::kDone ? 0.0 : reached > 0.0 ? model.core_s(rest.work) : est;
    const double upper = rest.packed_step_s > 0.0 ? model.core_s(rest.packed_work) : left;
    if (st != CaseStatus::kDone) {
      out.pending_costs.push_back(left);
      out.pending_costs_upper.push_back(upper);
    }
    // The step the rest is costed at, where the run's own step is below time.dt_cfd.
    const bool cut_step = reached > 0.0 && rest.fluid_step_s < c.params.time.dt_cfd_s;
    nlohmann::json row = {
        {"group", c.group},         {"swept", swept_text(c)},  {"case_id", c.id},
        {"state", to_string(st)},   {"estimated_core_s", est}, {"reached_s", reached},
        {"remaining_core_s", left}, {"scene", c.params.scene}, {"cost_basis", model.basis(c.params.scene)}};
    if (cut_step) row["remaining_fluid_step_s"] = rest.fluid_step_s;
    if (rest.packed_step_s > 0.0) {
      row["remaining_core_s_packed_bed"] = upper;
      row["packed_bed_step_s"] = rest.packed_step_s;
    }
    const std::string packed_text =
        rest.packed_step_s > 0.0 ? fmt::format("up to {} should a packed bed cut its step to {:.3g} ms",
                                               duration(upper), 1e3 * rest.packed_step_s)
                                 : std::string();
    const auto m = measured_by_id.find(c.id);
    if (m != measured_by_id.end()) row["measured_core_s"] = m->second->core_s;
    if (opt.check_model && m != measured_by_id.end()) {
      // Leave one out: the same model without this run.
      std::vector<MeasuredCost> others;
      for (const auto& f : finished)
        if (f.case_id != c.id) others.push_back(f);
      row["predicted_by_others_core_s"] = CostModel(others).core_s(m->second->work);
    }
    std::vector<std::string> cells{
        c.group, swept_text(c), c.id, to_string(st),
        reached > 0.0
            ? fmt::format("{} ({} left from t = {:g} s{}{})", duration(est), duration(left), reached,
                          cut_step ? fmt::format(" at its step of {:.3g} ms", 1e3 * rest.fluid_step_s)
                                   : std::string(),
                          packed_text.empty() ? std::string() : "; " + packed_text)
        : packed_text.empty() ? duration(est)
                              : fmt::format("{} ({})", duration(est), packed_text)};
    if (opt.check_model)
      cells.push_back(row.contains("predicted_by_others_core_s")
                          ? fmt::format("measured {}, from the others {}", duration(m->second->core_s),
                                        duration(row["predicted_by_others_core_s"].get<double>()))
                          : std::string("-"));
    out.table.add(std::move(cells));
    out.rows.push_back(row);
  }
  return out;
}

/// The rows with their numbers in seconds (the table shows them for people).
std::string plan_csv(const nlohmann::json& rows) {
  const char* cols[] = {"group",
                        "swept",
                        "case_id",
                        "state",
                        "scene",
                        "estimated_core_s",
                        "reached_s",
                        "remaining_core_s",
                        "remaining_fluid_step_s",
                        "remaining_core_s_packed_bed",
                        "packed_bed_step_s",
                        "measured_core_s",
                        "predicted_by_others_core_s",
                        "cost_basis"};
  std::string out;
  for (const char* c : cols) out += fmt::format("{}{}", out.empty() ? "" : ",", c);
  out += "\n";
  for (const auto& r : rows) {
    std::vector<std::string> cells;
    for (const char* c : cols) {
      const auto v = r.value(c, nlohmann::json());
      cells.push_back(v.is_string() ? v.get<std::string>()
                      : v.is_null() ? ""
                                    : fmt::format("{:.6g}", v.get<double>()));
    }
    out += report::csv_line(cells);
  }
  return out;
}

/// A line per group: a table of a million lines is read by nobody (--all, csv and json list them).
std::string plan_per_group(const Study& study, const nlohmann::json& rows) {
  std::map<std::string, std::array<double, 3>> groups;  // cases, to run, core-seconds to run
  for (std::size_t i = 0; i < study.cases.size(); ++i) {
    auto& g = groups[study.cases[i].group];
    g[0] += 1;
    if (rows[i]["state"] != "done") {
      g[1] += 1;
      g[2] += rows[i]["remaining_core_s"].get<double>();
    }
  }
  report::TextTable per_group({"group", "cases", "to run", "core time to run"}, {false, true, true, true});
  for (const auto& [name, g] : groups)
    per_group.add({name, fmt::format("{:.0f}", g[0]), fmt::format("{:.0f}", g[1]), duration(g[2])});
  return fmt::format("{}(more than {} cases: one line per group; --all lists every case)\n", per_group.str(),
                     kListEveryCaseMax);
}

/// The most a study's [refine] may still add: per curve of three points or more, the points
/// max_points leaves, each with as many replicas as its group may run, at the cost of the curve's
/// first case with refine's set applied (at a packed bed's stable step where the packed-bed limit
/// is on); the rounds run one after another, the curves of a round side by side.
struct RefineBudget {
  long long cases = 0;
  double core_s = 0.0, wall_s = 0.0;
  report::TextTable table{{"group", "setting", "added", "may add", "core time at most"},
                          {false, false, true, true, true}};
  nlohmann::json rows = nlohmann::json::array();
};

RefineBudget refine_budget(const Study& study, const CostModel& model, int jobs, int ranks) {
  RefineBudget b;
  std::vector<std::vector<double>> rounds;  // rounds[r]: core-seconds of the cases of round r
  for (const auto& curve : refine_series(study)) {
    const int added =
        static_cast<int>(std::count_if(curve.cases.begin(), curve.cases.end(), [](const StudyCase* c) {
          return c->refine_round >= 0 && c->replica == 0;
        }));
    // A curve of fewer points than bracket a peak gets none (stats::next_refinement stops there).
    const auto points = std::count_if(curve.cases.begin(), curve.cases.end(),
                                      [](const StudyCase* c) { return c->replica == 0; });
    const int left = points < stats::kBracketPoints ? 0 : std::max(0, study.refine->max_points - added);
    const auto plan = study.replica_plans.find(curve.group);
    const int replicas = plan == study.replica_plans.end() ? 1 : plan->second.max;
    // At most: where the packed-bed limit is on, at a packed bed's stable step.
    const Rest point = rest_of({}, refined_case(study, curve, curve.first->params.gravity.angle_deg, 0));
    const double point_s = model.core_s(point.upper_work());
    const long long cases = static_cast<long long>(left) * replicas;
    b.cases += cases;
    b.core_s += static_cast<double>(cases) * point_s;
    for (int r = 0; r < left; ++r) {
      if (rounds.size() <= static_cast<std::size_t>(r)) rounds.emplace_back();
      for (int k = 0; k < replicas; ++k) rounds[static_cast<std::size_t>(r)].push_back(point_s);
    }
    b.table.add({curve.group, curve.setting.empty() ? "-" : curve.setting, std::to_string(added),
                 std::to_string(cases), duration(static_cast<double>(cases) * point_s)});
    b.rows.push_back({{"group", curve.group},
                      {"setting", curve.setting},
                      {"added_points", added},
                      {"max_cases", cases},
                      {"max_core_s", static_cast<double>(cases) * point_s}});
  }
  for (const auto& r : rounds) b.wall_s += study_wall_s(r, jobs, ranks);
  return b;
}

/// What each scene's estimates rest on: its fitted runs, or the default model with its constants.
void print_cost_models(const Study& study, const CostModel& model) {
  std::map<std::string, bool> scenes;
  for (const auto& c : study.cases) scenes[c.params.scene] = true;
  for (const auto& [scene, _] : scenes)
    std::printf(
        "cost model %s: %s%s\n", scene.c_str(), model.basis(scene).c_str(),
        model.basis(scene) == "default"
            ? fmt::format(" ({:g} s + {:g} ns per particle-step + {:g} us per fluid cell-step)",
                          CostModel::kStartS, CostModel::kParticleStepS * 1e9, CostModel::kCellStepS * 1e6)
                  .c_str()
            : "");
}

}  // namespace

int study_plan(const PlanOptions& opt) {
  const ListingFormat format = parse_listing_format(opt.format);
  if (opt.jobs < 1 || opt.ranks < 1) throw InputError("--jobs and --ranks must be at least 1");
  Study study = expand_study_file(opt.study_file);
  // The plan reads an existing database and creates none.
  std::optional<Database> db;
  if (!opt.db_path.empty() && fs::exists(opt.db_path)) db.emplace(opt.db_path, OpenMode::kReadOnly);
  if (db) add_recorded_refinements(*db, study);
  std::map<std::string, CaseState> states;
  std::vector<MeasuredCost> finished;
  if (db) {
    // As `study status` sees them: an open attempt nobody holds (its driver was killed) is
    // interrupted, not running.
    for (auto& s : case_states_for(*db, opt.db_path, study, 2)) states[s.id] = s;
    finished = measured(*db);
  }
  const CostModel model(finished);
  const PlanRows plan = plan_rows(study, opt, states, finished, model);
  const double wall = study_wall_s(plan.pending_costs, opt.jobs, opt.ranks);
  const double wall_packed = study_wall_s(plan.pending_costs_upper, opt.jobs, opt.ranks);
  const RefineBudget refine = refine_budget(study, model, opt.jobs, opt.ranks);
  if (format == ListingFormat::kCsv) {
    std::fputs(plan_csv(plan.rows).c_str(), stdout);
    return 0;
  }
  if (format == ListingFormat::kJson) {
    nlohmann::json j{{"study", study.name},
                     {"cases", plan.rows},
                     {"jobs", opt.jobs},
                     {"ranks", opt.ranks},
                     {"remaining_cases", plan.pending_costs.size()},
                     {"estimated_wall_s", wall},
                     {"estimated_wall_s_packed_beds", wall_packed},
                     {"estimated_core_s_all_cases", plan.total_core_s}};
    if (study.refine)
      j["refinement"] = {{"max_cases", refine.cases},
                         {"max_core_s", refine.core_s},
                         {"max_wall_s", refine.wall_s},
                         {"curves", refine.rows}};
    std::printf("%s\n", j.dump(1).c_str());
    return 0;
  }
  std::printf("study %s: %s, %zu to run\n", study.name.c_str(),
              count_of(static_cast<long long>(study.cases.size()), "case").c_str(),
              plan.pending_costs.size());
  if (study.cases.size() <= kListEveryCaseMax || opt.all)
    std::printf("%s", plan.table.str().c_str());
  else
    std::fputs(plan_per_group(study, plan.rows).c_str(), stdout);
  std::printf("estimated wall time of the cases to run: %s on %s x %s (parallel efficiency %.2f)%s\n",
              duration(wall).c_str(), count_of(opt.jobs, "job").c_str(), count_of(opt.ranks, "rank").c_str(),
              ranks_efficiency(opt.ranks),
              wall_packed > wall ? fmt::format("; up to {} should the beds that the packed-bed limit steps "
                                               "for pack (numerics.drag_dt_limit)",
                                               duration(wall_packed))
                                       .c_str()
                                 : "");
  if (study.refine) {
    std::printf(
        "[refine] may add at most %s to its curves (max_points %d a curve, each point with its replicas), "
        "estimated at most %s of core time, %s of wall time on %s x %s after the cases above; at most %s "
        "all told:\n%s",
        count_of(refine.cases, "case").c_str(), study.refine->max_points, duration(refine.core_s).c_str(),
        duration(refine.wall_s).c_str(), count_of(opt.jobs, "job").c_str(),
        count_of(opt.ranks, "rank").c_str(), duration(wall + refine.wall_s).c_str(),
        refine.table.str().c_str());
  }
  print_cost_models(study, model);
  return 0;
}

}  // namespace boycott::driver
