#pragma once
// Process control of `study run`: the solver command, the run folder's lock, fork/exec of one
// solver with its output appended to solver.log, the driver's stop signal and its forwarding to
// the solvers, and the reaping of solvers that have exited. Nothing here reads the database.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "driver/run/run_folder_lock.hpp"

#include "driver/study/study.hpp"

namespace boycott::driver {

/// One solver started for one case: what the driver needs to stop, reap, record and show it.
struct RunningCase {
  const StudyCase* c = nullptr;
  std::filesystem::path dir;            ///< the run folder, <db>.runs/<case_id>
  int lock_fd = -1;                     ///< the run folder's lock, shared with the solver
  pid_t pid = -1;                       ///< also the solver's process group
  std::int64_t attempt = 0;             ///< attempts.id of this run
  std::uintmax_t log_offset_bytes = 0;  ///< size of solver.log before this attempt wrote to it
  /// Where this attempt's output in solver.log ends; unset: at the end of the file (`study
  /// collect` reads attempts that later attempts appended to).
  std::optional<std::uintmax_t> log_end_bytes;
  std::chrono::steady_clock::time_point started;
  double t_start_s = 0;  ///< simulated time when this attempt started (resume)
  /// summary.json's modification time before this attempt (none: there was none), to tell a
  /// summary this attempt wrote from an older one.
  std::optional<std::filesystem::file_time_type> summary_before;
};

/// The solver command line: `configured` split at spaces; empty: $BOYCOTT_SOLVER_COMMAND, else
/// this program.
std::vector<std::string> solver_argv(const std::string& configured);

/// The launcher: argv for one case, wrapped in mpirun when ranks > 1.
std::vector<std::string> case_command(const std::vector<std::string>& solver, int ranks,
                                      const std::string& case_file, const std::string& out_dir);

/// Starts argv in a process group of its own with stdout and stderr appended to `log`; the
/// solver inherits `lock_fd` and holds the run folder as long as it lives.
pid_t start_solver(const std::vector<std::string>& argv, const std::filesystem::path& log, int lock_fd);

/// From now on SIGINT and SIGTERM ask the driver to stop instead of ending it.
void install_stop_handlers();
/// The signal that asked the driver to stop; 0 while none has.
int stop_signal();
/// Asks a solver to checkpoint and stop: SIGTERM to its whole process group (mpirun included).
void forward_stop(pid_t pid);

struct SolverExit {
  pid_t pid = -1;
  int exit_code = 0;  ///< the exit status, or 128 + the signal that killed it
};
/// A child that has exited, without waiting; nullopt while none has.
std::optional<SolverExit> reap_exited_solver();

}  // namespace boycott::driver
