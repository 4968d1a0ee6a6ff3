#pragma once
// `boycott study submit --scheduler slurm`: the pending cases of a study as one Slurm job array.
// Each array task runs one case in its run folder, <db>.runs/<case_id>/, as `study run` does, and
// records each attempt there (attempts/*.json; attempt.json is the newest) without touching the
// database: the database is in WAL mode, which network file systems do not support, so one host
// collects the run folders into it (collect.hpp). The batch script asks for a warning before the
// time limit (--signal=B:USR1@120), runs the solver in the background so that its trap runs, hands
// the warning on (the solver checkpoints and exits 75) and requeues its job; a storage error (74)
// requeues it after a pause; other failures run the case again within the task up to --retries.
// Also: squeue's view of the jobs, for collect and `study status`.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace boycott::driver {

struct SlurmSubmitOptions {
  std::string study_file;
  std::string db_path;
  std::string scheduler = "slurm";  ///< the only one there is
  int ranks = 1;                    ///< MPI ranks per case (srun --mpi=pmix -n N, or mpirun -n N)
  int retries = 2;                  ///< failed attempts allowed beyond the first, as `study run`
  int max_running = 0;              ///< array tasks at once (%K); 0: as many as Slurm allows
  std::string time;  ///< --time of each task (HH:MM:SS, D-HH:MM:SS, ...); empty: the partition's
  std::string partition;
  /// How a case runs on several ranks: "mpirun" (the default: 2-rank launches under
  /// `srun --mpi=pmix` hung now and then here, docs/cluster.md) or "srun".
  std::string launcher = "mpirun";
  std::vector<std::string> sbatch_args;  ///< extra #SBATCH lines, e.g. --account=X
  bool dry_run = false;                  ///< print the script, write and submit nothing
  /// The solver command line (split at spaces); empty: $BOYCOTT_SOLVER_COMMAND, else this program.
  std::string solver_command;
};

/// Exit code: 0 submitted (or nothing to submit), 2 bad options or study, 1 sbatch failed.
int study_submit(const SlurmSubmitOptions& opt);

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
