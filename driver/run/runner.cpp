#include "driver/run/runner.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/report/curve.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/report/peak.hpp"
#include "driver/report/peak_query.hpp"
#include "driver/report/report_util.hpp"
#include "driver/report/validation_query.hpp"
#include "driver/run/collect.hpp"
#include "driver/run/plan.hpp"
#include "driver/run/progress.hpp"
#include "driver/run/refine_rounds.hpp"
#include "driver/run/replica_rounds.hpp"
#include "driver/run/run_tree.hpp"
#include "driver/run/scheduler.hpp"
#include "driver/run/slurm_commands.hpp"
#include "driver/run/solver_process.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"
#include "driver/store/store_slurm.hpp"
#include "driver/study/study.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

/// The cases the next round adds: replicas first (a point's error decides the refinement), then
/// refined points; none when neither has any to add.
std::vector<StudyCase> next_round(Database& db, const Study& s, int retries, std::set<std::string>& told) {
  if (has_replica_target(s)) {
    const ReplicaRound round = next_replica_round(db, s);
    if (!round.added.empty()) {
      std::fprintf(stderr, "replicas: %zu points get one more (%d within the target, %d at replicas_max)\n",
                   round.added.size(), round.precise, round.at_max);
      return round.added;
    }
  }
  if (!s.refine) return {};
  const RefineRound round = next_refine_round(db, s, retries);
  print_refine_round(round, told);
  return round.added;
}

/// The settling curve where the study has one, with its peaks under [refine]; otherwise (ergun,
/// single_particle, channel_flow, sediment_transport) each finished case's validation errors
/// against their tolerances.
void print_study_results(Database& db, const Study& study, int done) {
  const auto curve = query_curve(db, study.name);
  if (curve.empty() && done > 0) {
    std::fputs(format_validation(query_validation(db, study.name), ListingFormat::kTable).c_str(), stdout);
    return;
  }
  std::fputs(format_curve(curve, ListingFormat::kTable).c_str(), stdout);
  if (study.refine && !curve.empty()) {
    std::printf("peak (query peak):\n");
    std::fputs(format_peak(query_peak(db, study.name), ListingFormat::kTable).c_str(), stdout);
  }
}

/// The cases neither done nor failed.
std::vector<std::string> ids_to_run(const std::vector<CaseState>& states) {
  std::vector<std::string> ids;
  for (const auto& s : states)
    if (s.status != CaseStatus::kDone && s.status != CaseStatus::kFailed) ids.push_back(s.id);
  return ids;
}

}  // namespace

int study_run(const StudyRunOptions& options) {
  StudyRunOptions opt = options;
  if (opt.stop_after_s > 0.0)
    opt.stop_at =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(opt.stop_after_s));
  if (opt.jobs < 1) throw InputError(fmt::format("--jobs = {} must be >= 1", opt.jobs));
  if (opt.retries < 0) throw InputError(fmt::format("--retries = {} must be >= 0", opt.retries));
  if (opt.ranks < 1) throw InputError(fmt::format("--ranks = {} must be >= 1", opt.ranks));
  // The whole study is expanded and validated before the database is touched.
  Study study = expand_study_file(opt.study_file);
  Database db(opt.db_path, OpenMode::kCreate);
  const fs::path root = runs_root(opt.db_path);
  // The points [refine] added in earlier runs are cases of the study as its file lists them.
  add_recorded_refinements(db, study);
  prepare_study_database(db, study, root);
  // What Slurm tasks (study submit) left in the run folders; the cases still in Slurm jobs stay
  // theirs.
  const CollectResult collected = collect_run_folders(db, study, root);
  update_run_tree(study, opt.db_path, root);
  if (collected.results > 0 || collected.attempts > 0 || collected.abandoned > 0)
    std::fprintf(stderr, "collected %d results and %d attempt ends, closed %d abandoned attempts\n",
                 collected.results, collected.attempts, collected.abandoned);
  if (!collected.in_slurm.empty())
    std::fprintf(stderr,
                 "%zu cases are in Slurm jobs (queued or running) and are left to them: `boycott study "
                 "collect` records them when they end\n",
                 collected.in_slurm.size());
  fs::create_directories(root);
  auto solver = solver_argv(opt.solver_command);
  install_stop_handlers();

  auto states = case_states(db, study.name, opt.retries);
  std::erase_if(states, [&](const CaseState& s) { return collected.in_slurm.count(s.id) > 0; });
  const std::vector<std::string> to_run = ids_to_run(states);
  const PlanEstimate plan = plan_estimate(db, study, to_run, opt.jobs, opt.ranks, root);
  if (!to_run.empty()) std::fprintf(stderr, "%s\n", plan.line.c_str());
  Scheduler scheduler(db, study, states, opt, root, solver);
  scheduler.set_plan(plan.cases);
  bool stopped = scheduler.run();
  std::string storage_stop = scheduler.storage_stop();
  // Rounds: replicas where a point's scatter is too large (replicas_target_rel_error), then
  // points where a curve's peak is not known well enough ([refine]), until neither adds a case.
  Study grown = study;
  std::set<std::string> told;
  while (!stopped && storage_stop.empty()) {
    std::vector<StudyCase> more = next_round(db, grown, opt.retries, told);
    if (more.empty()) break;
    grown.cases.insert(grown.cases.end(), more.begin(), more.end());
    register_study(db, grown);
    update_run_tree(grown, opt.db_path, root);
    auto more_states = case_states(db, grown.name, opt.retries);
    std::erase_if(more_states, [&](const CaseState& s) { return collected.in_slurm.count(s.id) > 0; });
    Scheduler more_runs(db, grown, more_states, opt, root, solver);
    more_runs.set_plan(plan_estimate(db, grown, ids_to_run(more_states), opt.jobs, opt.ranks, root).cases);
    stopped = more_runs.run();
    storage_stop = more_runs.storage_stop();
  }
  if (!storage_stop.empty()) {
    std::fprintf(stderr, "error: study %s stopped: %s; once the storage works again, run the same command\n",
                 study.name.c_str(), storage_stop.c_str());
    return kExitStorageError;
  }

  const int n_total = static_cast<int>(grown.cases.size());
  int done = 0, failed = 0;
  for (const auto& s : case_states(db, study.name, opt.retries)) {
    done += s.status == CaseStatus::kDone;
    failed += s.status == CaseStatus::kFailed;
  }
  if (stopped) {
    const std::string by = stop_signal() ? fmt::format("by signal {}", stop_signal())
                                         : fmt::format("after --stop-after {:g} s", opt.stop_after_s);
    std::printf("study %s stopped %s: %d of %s done; run the same command to resume\n", study.name.c_str(),
                by.c_str(), done, count_of(n_total, "case").c_str());
    return kExitInterrupted;
  }
  std::printf("study %s: %d of %s done, %d failed\n", study.name.c_str(), done,
              count_of(n_total, "case").c_str(), failed);
  print_study_results(db, study, done);
  return failed > 0 ? kExitFailure : kExitOk;
}

std::vector<CaseState> case_states_now(Database& db, const std::string& db_path, const std::string& study,
                                       int retries) {
  auto states = case_states(db, study, retries);
  std::set<std::string> in_slurm;
  if (has_slurm_columns(db))
    for (const auto& a : slurm_attempts(db, study, true)) in_slurm.insert(a.case_id);
  // An open attempt whose folder nobody holds, and no Slurm task owns: its driver died (kill -9,
  // power loss). A task not yet started holds no folder, and is running as far as we know.
  for (auto& c : states)
    if (c.status == CaseStatus::kRunning && !in_slurm.count(c.id) &&
        run_folder_unheld(fs::path(runs_root(db_path)) / c.id))
      c.status = CaseStatus::kInterrupted;
  return states;
}

std::vector<CaseState> case_states_for(Database& db, const std::string& db_path, const Study& study,
                                       int retries) {
  auto states = case_states_now(db, db_path, study.name, retries);
  // The database holds each case's parameters as of the last `study run`: a time.end raised in the
  // file since then leaves a result short of it, and `study run` will continue the case.
  std::map<std::string, const StudyCase*> by_id;
  for (const auto& c : study.cases) by_id[c.id] = &c;
  for (auto& s : states)
    if (s.status == CaseStatus::kDone && by_id.count(s.id) &&
        !result_reaches_end(db, s.id, to_json(by_id.at(s.id)->params).dump()))
      s.status = CaseStatus::kPending;
  return states;
}

int study_status(const std::string& study_file, const std::string& db_path, int retries,
                 ListingFormat format) {
  Study study = expand_study_file(study_file);
  // A status reads a database and creates none: a missing one is most likely a mistyped path
  // (the cases of a study not yet run are listed by `study plan`).
  if (!fs::exists(db_path))
    throw InputError(
        fmt::format("no database at '{}' (`boycott study plan {}` lists the cases of a study not "
                    "yet run)",
                    db_path, study_file));
  std::optional<Database> db;
  db.emplace(db_path, OpenMode::kReadOnly);
  add_recorded_refinements(*db, study);
  std::map<std::string, CaseState> known;
  for (auto& s : case_states_for(*db, db_path, study, retries)) known[s.id] = s;
  // Cases submitted to Slurm (study submit): their array task and, where squeue answers, its state.
  std::map<std::string, std::string> jobs;
  std::optional<std::vector<SlurmJob>> queue;
  std::string queue_why;
  const auto open_slurm =
      db && has_slurm_columns(*db) ? slurm_attempts(*db, study.name, true) : std::vector<SlurmAttempt>{};
  if (!open_slurm.empty()) queue = squeue_jobs(&queue_why);
  for (const auto& a : open_slurm) {
    const SlurmJob* job = queue ? find_slurm_job(*queue, a.array_job_id, a.array_task_id, a.job_id) : nullptr;
    jobs[a.case_id] = fmt::format("{}_{} {}", a.array_job_id.value_or(0), a.array_task_id.value_or(0),
                                  !queue ? "?"
                                  : job  ? job->state
                                         : "ended");
  }
  int uncollected = 0;
  std::map<std::string, int> counts;
  std::vector<std::string> header = {"case", "group", "angle_deg", "status", "ranks"};
  std::vector<bool> numeric = {false, false, true, false, true};
  if (!jobs.empty()) {
    header.push_back("slurm_job");
    numeric.push_back(false);
  }
  // How far each started case has got, from its run folder's time series (a running case's
  // progress; where an interrupted one resumes, at most a checkpoint interval earlier).
  header.insert(header.end(), {"reached_s", "last_error"});
  numeric.insert(numeric.end(), {true, false});
  report::TextTable table(header, numeric);
  const fs::path runs = runs_root(db_path);
  for (const auto& c : study.cases) {
    auto it = known.find(c.id);
    const char* st = it == known.end() ? "pending" : to_string(it->second.status);
    const auto job = jobs.find(c.id);
    ++counts[st];
    if ((it == known.end() || it->second.status != CaseStatus::kDone) &&
        collectable_summary(*db, runs / c.id, c.id))
      ++uncollected;
    std::vector<std::string> row = {
        c.id, c.group, fmt::format("{:.1f}", c.params.gravity.angle_deg), st,
        it != known.end() && it->second.ranks > 0 ? std::to_string(it->second.ranks) : "-"};
    if (!jobs.empty()) row.push_back(job == jobs.end() ? "-" : job->second);
    const double reached = it == known.end() ? 0.0 : simulated_time_s(runs / c.id);
    row.push_back(reached > 0.0 ? fmt::format("{:.3f}", reached) : "-");
    // A running case's last error is its previous attempt's, not what it is doing now.
    const bool shown =
        it != known.end() && it->second.status != CaseStatus::kDone && !it->second.last_error.empty();
    row.push_back(!shown                                      ? ""
                  : it->second.status == CaseStatus::kRunning ? "previous attempt: " + it->second.last_error
                                                              : it->second.last_error);
    table.add(std::move(row));
  }
  const char* kStates[] = {"done", "running", "failed", "interrupted", "pending"};
  if (format == ListingFormat::kCsv) {
    std::fputs(table.csv().c_str(), stdout);
    return 0;
  }
  if (format == ListingFormat::kJson) {
    nlohmann::json j = {{"study", study.name},
                        {"cases_total", study.cases.size()},
                        {"uncollected_run_folders", uncollected},
                        {"slurm_states_unknown", !open_slurm.empty() && !queue ? queue_why : ""},
                        {"cases", table.json()}};
    for (const char* st : kStates) j["counts"][st] = counts[st];
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("study %s: %s: %d done, %d running, %d failed, %d interrupted, %d pending\n",
              study.name.c_str(), count_of(static_cast<long long>(study.cases.size()), "case").c_str(),
              counts["done"], counts["running"], counts["failed"], counts["interrupted"], counts["pending"]);
  if (!open_slurm.empty() && !queue) std::printf("Slurm job states unknown: %s\n", queue_why.c_str());
  if (uncollected > 0)
    std::printf("%d finished run folders are not recorded yet: boycott study collect %s --db %s\n",
                uncollected, study_file.c_str(), db_path.c_str());
  std::fputs(table.str().c_str(), stdout);
  return 0;
}

}  // namespace boycott::driver
