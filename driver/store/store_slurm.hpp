#pragma once
// The study database's rows of attempts run as Slurm array tasks (results_schema/004_slurm.sql):
// what `study submit` records when it submits, and what `study collect` copies from the tasks'
// attempt records. Each function that writes is one transaction; the SQL lives in store_slurm.cpp.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driver/store/database.hpp"

namespace boycott::driver {

/// One case submitted as task `array_task_id` of a job array.
struct SubmittedCase {
  std::string case_id;
  std::string run_dir;
  std::int64_t array_task_id = 0;
};

/// Opens one attempt per case (host "slurm", no end) carrying the array job and task ids; closes
/// any attempt of those cases left open before.
void record_submission(Database& db, std::int64_t array_job_id, int ranks,
                       const std::vector<SubmittedCase>& cases);

/// An attempt as a task recorded it in its run folder (attempts/<file>.json).
struct TaskAttemptRecord {
  std::string case_id, file, host, started_at, run_dir, program_version;
  int ranks = 1;
  std::int64_t job_id = 0, array_job_id = 0, array_task_id = 0, restart = 0;
};

/// An attempt row of a Slurm task; unset where the column is NULL.
struct SlurmAttempt {
  std::int64_t id = 0;
  std::string case_id;
  std::optional<std::int64_t> array_job_id, array_task_id, job_id;
  std::optional<std::string> attempt_file, ended_at;
  std::optional<int> exit_status;
};

/// The row of `r`: the one that collected the same file, else the attempt that `study submit`
/// opened for its array task (not yet matched to a file), else a new one; its host, ranks, start
/// and job ids set from `r`. Its end is left as it was.
SlurmAttempt upsert_task_attempt(Database& db, const TaskAttemptRecord& r);

/// Sets an attempt's start and end as its task recorded them.
void set_attempt_times(Database& db, std::int64_t attempt, const std::string& started_at,
                       const std::string& ended_at);

/// Closes an attempt that is still open without an exit status ("abandoned: <why>").
void abandon_attempt(Database& db, std::int64_t attempt, const std::string& why);

/// The attempts with a Slurm array job of the study's cases (every study when `study` is empty),
/// oldest first; only the open ones with open_only.
std::vector<SlurmAttempt> slurm_attempts(Database& db, const std::string& study, bool open_only);

/// The newest attempt of the case that has no end yet.
std::optional<std::int64_t> latest_open_attempt(Database& db, const std::string& case_id);

/// Whether the database has the Slurm columns (schema version 4; a read-only query does not
/// migrate an older one).
bool has_slurm_columns(Database& db);

}  // namespace boycott::driver
