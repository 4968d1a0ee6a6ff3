#pragma once
// `boycott study submit --scheduler slurm`: the pending cases of a study as one Slurm job array.
// Each array task runs one case in its run folder, <db>.runs/<case_id>/, as `study run` does, and
// records each attempt there (attempts/*.json; attempt.json is the newest) without touching the
// database: the database is in WAL mode, which network file systems do not support, so one host
// collects the run folders into it (collect.hpp). The batch script asks for a warning before the
// time limit (--signal=B:USR1@120), runs the solver in the background so that its trap runs, hands
// the warning on (the solver checkpoints and exits 75) and requeues its job; a storage error (74)
// requeues it after a pause; other failures run the case again within the task up to --retries.
// squeue's view of the jobs, for collect and `study status`: slurm_commands.hpp.
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

}  // namespace boycott::driver
