#include "driver/run/collect.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "driver/run/recording.hpp"
#include "driver/run/refine_rounds.hpp"
#include "driver/run/run_tree.hpp"
#include "driver/run/slurm_commands.hpp"
#include "driver/run/solver_process.hpp"
#include "driver/store/case_id_migration.hpp"
#include "driver/store/store.hpp"
#include "driver/store/store_slurm.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

/// One attempt as its task recorded it (attempts/<name>.json; slurm.cpp writes them).
struct AttemptRecord {
  std::string name;
  TaskAttemptRecord row;
  std::optional<std::string> ended_at;
  std::optional<int> exit_code;
  std::uintmax_t log_offset = 0;
  std::optional<std::uintmax_t> log_end;
  std::optional<std::string> set_aside;  ///< where exit 4 moved the attempt's outputs
};

std::optional<nlohmann::json> read_json(const fs::path& p) {
  std::ifstream in(p);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return nlohmann::json::parse(ss.str());
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

template <class T>
std::optional<T> field(const nlohmann::json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return std::nullopt;
  try {
    return j[key].get<T>();
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

/// The case's attempt records, oldest first. Records are renamed into place whole, so one that
/// does not parse is not ours (or damaged): it is named and skipped.
std::vector<AttemptRecord> attempt_records(const StudyCase& c, const fs::path& dir) {
  std::vector<AttemptRecord> out;
  std::error_code ec;
  if (!fs::is_directory(dir / "attempts", ec)) return out;
  for (const auto& e : fs::directory_iterator(dir / "attempts", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.' || e.path().extension() != ".json") continue;
    const auto j = read_json(e.path());
    const auto started = j ? field<std::string>(*j, "started_at") : std::nullopt;
    if (!j || !started || field<std::string>(*j, "case_id").value_or("") != c.id) {
      std::fprintf(stderr, "case %s: %s is not an attempt record of this case; skipped\n", c.id.c_str(),
                   e.path().c_str());
      continue;
    }
    AttemptRecord r;
    r.name = name;
    r.row.case_id = c.id;
    r.row.file = name;
    r.row.host = field<std::string>(*j, "host").value_or("?");
    r.row.started_at = *started;
    r.row.run_dir = dir.string();
    r.row.program_version = field<std::string>(*j, "program_version").value_or("?");
    r.row.ranks = field<int>(*j, "ranks").value_or(1);
    r.row.job_id = field<std::int64_t>(*j, "slurm_job_id").value_or(0);
    r.row.array_job_id = field<std::int64_t>(*j, "slurm_array_job_id").value_or(r.row.job_id);
    r.row.array_task_id = field<std::int64_t>(*j, "slurm_array_task_id").value_or(0);
    r.row.restart = field<std::int64_t>(*j, "restart_count").value_or(0);
    r.ended_at = field<std::string>(*j, "ended_at");
    r.exit_code = field<int>(*j, "exit_code");
    r.log_offset = field<std::uintmax_t>(*j, "log_offset_bytes").value_or(0);
    r.log_end = field<std::uintmax_t>(*j, "log_end_bytes");
    r.set_aside = field<std::string>(*j, "set_aside");
    if (r.ended_at.has_value() != r.exit_code.has_value()) r.ended_at.reset(), r.exit_code.reset();
    out.push_back(std::move(r));
  }
  std::sort(out.begin(), out.end(), [](const AttemptRecord& a, const AttemptRecord& b) {
    return std::tie(a.row.started_at, a.name) < std::tie(b.row.started_at, b.name);
  });
  return out;
}

/// Whether a process on this host holds the run folder (a solver of `study run`, or a task).
/// Over NFS the lock may not work: then this says no, and summary.json's status decides.
bool held_here(const fs::path& dir) {
  return fs::exists(dir / ".lock") && !run_folder_unheld(dir);
}

/// The case's finished summary.json (completed or converged, this case's id); nullopt otherwise.
std::optional<nlohmann::json> finished_summary(const std::string& case_id, const fs::path& dir) {
  auto s = read_json(dir / "summary.json");
  if (!s || !is_finished_status(s->value("status", "")) || s->value("case_id", "") != case_id)
    return std::nullopt;
  return s;
}

}  // namespace

std::optional<nlohmann::json> collectable_summary(Database& db, const fs::path& dir,
                                                  const std::string& case_id) {
  auto s = finished_summary(case_id, dir);
  if (s && !summary_reaches_end(db, case_id, s->dump())) s.reset();
  return s;
}

void prepare_study_database(Database& db, const Study& study, const fs::path& runs_root) {
  // Ids of an older identity scheme become this one's before the study's cases are matched.
  const IdMigration moved = migrate_case_ids(db, runs_root);
  if (moved.cases > 0)
    std::fprintf(stderr,
                 "case identity version %d: %d case ids recomputed (%d merged), %d run folders renamed\n",
                 kCaseIdVersion, moved.cases, moved.merged, moved.folders);
  register_study(db, study);
}

CollectResult collect_run_folders(Database& db, const Study& study, const fs::path& runs_root) {
  CollectResult out;
  for (const auto& c : study.cases) {
    const fs::path dir = runs_root / c.id;
    bool done = has_result(db, c.id);
    const auto records = attempt_records(c, dir);
    std::error_code ec;
    const auto summary_mtime = fs::last_write_time(dir / "summary.json", ec);
    for (std::size_t i = 0; i < records.size(); ++i) {
      const AttemptRecord& r = records[i];
      const SlurmAttempt row = upsert_task_attempt(db, r.row);
      if (!r.exit_code) {
        // Started, never ended: running, or its task died. A newer attempt means the latter.
        if (i + 1 < records.size() && !row.ended_at) {
          abandon_attempt(
              db, row.id,
              "the task stopped without recording the attempt's end (killed, or its node failed)");
          ++out.abandoned;
        }
        continue;
      }
      if (row.ended_at == r.ended_at) continue;  // recorded before
      RunningCase run;
      run.c = &c;
      run.dir = r.set_aside ? fs::path(*r.set_aside) : dir;
      run.attempt = row.id;
      run.log_offset_bytes = r.log_offset;
      run.log_end_bytes = r.log_end;
      // A summary newer attempts rewrote is not this attempt's (recording.cpp compares times).
      if (i + 1 < records.size() && !ec) run.summary_before = summary_mtime;
      if (*r.exit_code == 0 && done) {
        finish_attempt(db, row.id, 0, "");
      } else {
        const AttemptEnd end = record_attempt_end(db, run, *r.exit_code);
        if (end.kind == AttemptEnd::Kind::kDone) {
          done = true;
          ++out.results;
        }
      }
      set_attempt_times(db, row.id, r.row.started_at, *r.ended_at);
      ++out.attempts;
    }
    if (done || held_here(dir)) continue;
    // A finished summary that no attempt record brought in: the task ended the solver but not yet
    // its record, or the folder was run by hand or by a driver that died.
    // One that stopped at an earlier time.end than the case now has is continued, not recorded.
    if (const auto s = collectable_summary(db, dir, c.id)) {
      auto attempt = latest_open_attempt(db, c.id);
      if (!attempt) attempt = begin_attempt(db, c.id, s->value("mpi_ranks", 1), dir.string());
      if (record_left_summary(db, *attempt, c.id, dir)) ++out.results;
    }
  }

  const auto open = slurm_attempts(db, study.name, true);
  if (open.empty()) return out;
  std::string why;
  const auto jobs = squeue_jobs(&why);
  for (const auto& a : open) {
    const SlurmJob* job = jobs ? find_slurm_job(*jobs, a.array_job_id, a.array_task_id, a.job_id) : nullptr;
    if (!jobs || job) {
      out.in_slurm.insert(a.case_id);
      continue;
    }
    const std::string task = fmt::format("{}_{}", a.array_job_id.value_or(0), a.array_task_id.value_or(0));
    abandon_attempt(db, a.id,
                    a.attempt_file
                        ? fmt::format("Slurm job {} ended without recording the attempt's end "
                                      "(time limit, cancelled, or its node failed)",
                                      task)
                        : fmt::format("Slurm job {} left the queue without starting (cancelled?)", task));
    ++out.abandoned;
  }
  if (!jobs) std::fprintf(stderr, "note: %s; open Slurm attempts are left as they are\n", why.c_str());
  return out;
}

int study_collect(const std::string& study_file, const std::string& db_path, int retries) {
  Study study = expand_study_file(study_file);
  Database db(db_path, OpenMode::kCreate);
  const fs::path root = runs_root(db_path);
  // Points [refine] added (by study submit) are cases of the study: their folders are collected.
  add_recorded_refinements(db, study);
  prepare_study_database(db, study, root);
  const CollectResult r = collect_run_folders(db, study, root);
  update_run_tree(study, db_path, root);
  std::map<CaseStatus, int> n;
  for (const auto& s : case_states(db, study.name, retries)) ++n[s.status];
  std::printf(
      "study %s: collected %d results and %d attempt ends, closed %d abandoned attempts; %zu cases: %d done, "
      "%d running (%zu in Slurm jobs), %d failed, %d interrupted, %d pending\n",
      study.name.c_str(), r.results, r.attempts, r.abandoned, study.cases.size(), n[CaseStatus::kDone],
      n[CaseStatus::kRunning], r.in_slurm.size(), n[CaseStatus::kFailed], n[CaseStatus::kInterrupted],
      n[CaseStatus::kPending]);
  return 0;
}

}  // namespace boycott::driver
