#pragma once
// The driver's use of Slurm's command-line tools: finding and running one (sbatch, squeue) with
// its output captured, and squeue's view of the jobs, which `study submit`, `study collect` and
// `study status` read to tell a queued or running task from one that has left the queue.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace boycott::driver {

/// The program `name` on PATH (or `name` itself when it holds a '/'); nullopt when there is none.
std::optional<std::string> find_program(const std::string& name);

struct Captured {
  int exit_code = 0;  ///< or 128 + the signal that killed it
  std::string out, err;
};

/// Runs argv (found on PATH), stdin from /dev/null, and returns its exit and both outputs.
Captured run_captured(const std::vector<std::string>& argv);

/// s without leading and trailing white space.
std::string trim(std::string s);
/// The whole of s as a decimal integer; nullopt when it is not one.
std::optional<std::int64_t> to_int(const std::string& s);

/// One job (or array task) as squeue lists it.
struct SlurmJob {
  std::int64_t job_id = 0;        ///< %A: the task's own job id (the array's id while pending as a whole)
  std::int64_t array_job_id = 0;  ///< %F: the array's job id (job_id for a plain job)
  std::optional<std::int64_t> array_task_id;  ///< %K
  std::string state;                          ///< PENDING, RUNNING, COMPLETING, ...
  std::string reason;                         ///< %r
};

/// Every job squeue lists (array tasks one by one); nullopt, with the reason in *why, when there
/// is no squeue on PATH or it fails (no controller).
std::optional<std::vector<SlurmJob>> squeue_jobs(std::string* why = nullptr);

/// The listed job of array task (array_job_id, array_task_id), or of job_id; nullptr if none.
const SlurmJob* find_slurm_job(const std::vector<SlurmJob>& jobs, std::optional<std::int64_t> array_job_id,
                               std::optional<std::int64_t> array_task_id, std::optional<std::int64_t> job_id);

}  // namespace boycott::driver
