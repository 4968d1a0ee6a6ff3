#pragma once
// `boycott study run|status`: runs the missing cases of a study as child processes
// (`boycott case run CASE --out DIR`, optionally under mpirun), records every attempt and result
// in the study database, and resumes, skips or retries cases from what the database says.
// study_run sets up and reports; the parts: scheduler.hpp (queue, slots, retries, stop),
// solver_process.hpp (locks, fork/exec, signals, reaping), recording.hpp (run folder to rows),
// progress.hpp (live display). None of them holds SQL: they read and write through store.hpp.
#include <string>
#include <vector>

#include "driver/database.hpp"
#include "driver/listing_format.hpp"
#include "driver/store.hpp"

namespace boycott::driver {

struct StudyRunOptions {
  std::string study_file;
  std::string db_path;
  int jobs = 1;
  int retries = 2;  ///< failed attempts allowed beyond the first, over all runs of the study
  int ranks = 1;    ///< > 1: each case under `mpirun -n ranks`
  /// The solver command line (split at spaces); empty: $BOYCOTT_SOLVER_COMMAND, else this program.
  std::string solver_command;
  bool progress_live = false;      ///< redrawn in place (stderr is a terminal)
  double progress_every_s = 30.0;  ///< otherwise a plain block this often (<= 0: none)
};

/// Exit code: 0 all cases done, 75 stopped by a signal, 1 some case failed for good, 74 stopped
/// after storage errors in a row (Scheduler::kStorageFailuresToStop).
int study_run(const StudyRunOptions& opt);
/// case_states, with an open attempt whose run folder no process holds (and no Slurm task owns)
/// as interrupted: the one vocabulary of `study status` and `query cases`.
std::vector<CaseState> case_states_now(Database& db, const std::string& db_path, const std::string& study,
                                       int retries);
/// The study's cases and their states (pending without a database; none is created).
int study_status(const std::string& study_file, const std::string& db_path, int retries,
                 ListingFormat format = ListingFormat::kTable);

/// The folder where the cases of the database at db_path run: <db_path>.runs/<case_id>/.
std::string runs_root(const std::string& db_path);

/// The launcher: argv for one case, wrapped in mpirun when ranks > 1.
std::vector<std::string> case_command(const std::vector<std::string>& solver, int ranks,
                                      const std::string& case_file, const std::string& out_dir);

}  // namespace boycott::driver
