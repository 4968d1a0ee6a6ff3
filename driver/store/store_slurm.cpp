#include "driver/store/store_slurm.hpp"

#include <fmt/format.h>

#include "core/version.hpp"

namespace boycott::driver {

namespace {

SlurmAttempt read_attempt(Statement& st) {
  // Columns: id, case_id, slurm_array_job_id, slurm_array_task_id, slurm_job_id, attempt_file,
  // ended_at, exit_status.
  SlurmAttempt a;
  a.id = st.integer(0);
  a.case_id = st.text(1);
  if (!st.is_null(2)) a.array_job_id = st.integer(2);
  if (!st.is_null(3)) a.array_task_id = st.integer(3);
  if (!st.is_null(4)) a.job_id = st.integer(4);
  if (!st.is_null(5)) a.attempt_file = st.text(5);
  if (!st.is_null(6)) a.ended_at = st.text(6);
  if (!st.is_null(7)) a.exit_status = static_cast<int>(st.integer(7));
  return a;
}

constexpr const char* kAttemptColumns =
    "a.id, a.case_id, a.slurm_array_job_id, a.slurm_array_task_id, a.slurm_job_id, a.attempt_file, "
    "a.ended_at, a.exit_status";

}  // namespace

void record_submission(Database& db, std::int64_t array_job_id, int ranks,
                       const std::vector<SubmittedCase>& cases) {
  db.transaction([&] {
    const auto now = utc_now();
    for (const auto& c : cases) {
      db.prepare(
            "UPDATE attempts SET ended_at = ?2, error_text = 'abandoned: left open when the case was "
            "submitted to Slurm' WHERE case_id = ?1 AND ended_at IS NULL")
          .bind(1, c.case_id)
          .bind(2, now)
          .run();
      db.prepare(
            "INSERT INTO attempts(case_id, started_at, host, ranks, program_version, run_dir, "
            "slurm_array_job_id, slurm_array_task_id) VALUES (?1, ?2, 'slurm', ?3, ?4, ?5, ?6, ?7)")
          .bind(1, c.case_id)
          .bind(2, now)
          .bind(3, ranks)
          .bind(4, fmt::format("{}+{}", kVersion, kGitRevision))
          .bind(5, c.run_dir)
          .bind(6, array_job_id)
          .bind(7, c.array_task_id)
          .run();
    }
  });
}

SlurmAttempt upsert_task_attempt(Database& db, const TaskAttemptRecord& r) {
  SlurmAttempt out;
  db.transaction([&] {
    std::optional<std::int64_t> id;
    {
      auto st = db.prepare("SELECT id FROM attempts WHERE case_id = ?1 AND attempt_file = ?2");
      st.bind(1, r.case_id).bind(2, r.file);
      if (st.step()) id = st.integer(0);
    }
    if (!id) {
      // The attempt `study submit` opened for this array task, while no file has claimed it.
      auto st = db.prepare(
          "SELECT id FROM attempts WHERE case_id = ?1 AND slurm_array_job_id = ?2 AND slurm_array_task_id = "
          "?3 "
          "AND attempt_file IS NULL ORDER BY id LIMIT 1");
      st.bind(1, r.case_id).bind(2, r.array_job_id).bind(3, r.array_task_id);
      if (st.step()) id = st.integer(0);
    }
    if (!id) {
      // A new row with its case; the UPDATE below writes every other field, as for a known row.
      db.prepare(
            "INSERT INTO attempts(case_id, started_at, host, ranks, program_version) VALUES (?1, '', '', 0, "
            "'')")
          .bind(1, r.case_id)
          .run();
      auto st = db.prepare("SELECT last_insert_rowid()");
      st.step();
      id = st.integer(0);
    }
    db.prepare(
          "UPDATE attempts SET started_at = ?2, host = ?3, ranks = ?4, program_version = ?5, run_dir = ?6, "
          "attempt_file = ?7, slurm_job_id = ?8, slurm_array_job_id = ?9, slurm_array_task_id = ?10, "
          "slurm_restart = ?11 WHERE id = ?1")
        .bind(1, *id)
        .bind(2, r.started_at)
        .bind(3, r.host)
        .bind(4, r.ranks)
        .bind(5, r.program_version)
        .bind(6, r.run_dir)
        .bind(7, r.file)
        .bind(8, r.job_id)
        .bind(9, r.array_job_id)
        .bind(10, r.array_task_id)
        .bind(11, r.restart)
        .run();
    auto st = db.prepare(fmt::format("SELECT {} FROM attempts a WHERE a.id = ?1", kAttemptColumns));
    st.bind(1, *id);
    st.step();
    out = read_attempt(st);
  });
  return out;
}

void set_attempt_times(Database& db, std::int64_t attempt, const std::string& started_at,
                       const std::string& ended_at) {
  db.transaction([&] {
    db.prepare("UPDATE attempts SET started_at = ?2, ended_at = ?3 WHERE id = ?1")
        .bind(1, attempt)
        .bind(2, started_at)
        .bind(3, ended_at)
        .run();
  });
}

void abandon_attempt(Database& db, std::int64_t attempt, const std::string& why) {
  db.transaction([&] {
    db.prepare("UPDATE attempts SET ended_at = ?2, error_text = ?3 WHERE id = ?1 AND ended_at IS NULL")
        .bind(1, attempt)
        .bind(2, utc_now())
        .bind(3, "abandoned: " + why)
        .run();
  });
}

std::vector<SlurmAttempt> slurm_attempts(Database& db, const std::string& study, bool open_only) {
  auto st = db.prepare(fmt::format(
      "SELECT {} FROM attempts a WHERE a.slurm_array_job_id IS NOT NULL AND (?2 = 0 OR a.ended_at IS NULL) "
      "AND (?1 = '' OR a.case_id IN (SELECT case_id FROM study_cases WHERE study = ?1)) ORDER BY a.id",
      kAttemptColumns));
  st.bind(1, study).bind(2, open_only ? 1 : 0);
  std::vector<SlurmAttempt> out;
  while (st.step()) out.push_back(read_attempt(st));
  return out;
}

std::optional<std::int64_t> latest_open_attempt(Database& db, const std::string& case_id) {
  auto st =
      db.prepare("SELECT id FROM attempts WHERE case_id = ?1 AND ended_at IS NULL ORDER BY id DESC LIMIT 1");
  st.bind(1, case_id);
  if (!st.step()) return std::nullopt;
  return st.integer(0);
}

bool has_slurm_columns(Database& db) {
  return db.version() >= 4;
}

}  // namespace boycott::driver
