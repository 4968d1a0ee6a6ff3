#pragma once
// Recording: turns the run folder of an attempt (the solver's exit code, its summary.json, the
// last line of solver.log) into the attempt's and the result's rows in the study database,
// through the store.
#include <cstdint>
#include <filesystem>
#include <string>

#include "driver/run/solver_process.hpp"
#include "driver/store/database.hpp"

namespace boycott::driver {

/// How an attempt ended, as recorded.
struct AttemptEnd {
  /// kStorageFailed: the solver exited 74 (a write failed: disk full, I/O error); not the case's
  /// fault, so not a failure of it.
  enum class Kind { kDone, kInterrupted, kFailed, kStorageFailed };
  Kind kind = Kind::kFailed;
  int exit_code = 0;   ///< as recorded: 1 for an exit 0 without a usable summary.json
  std::string reason;  ///< why it failed, as recorded; empty unless kFailed or kStorageFailed
};

/// Closes the attempt of `run`, whose solver exited with `exit_code`: with its result (exit 0 and
/// a summary.json for this case), as interrupted (75, or 128 + SIGINT/SIGTERM: stopped before
/// the solver installed its handlers), as a storage failure (74), else as failed with the reason.
AttemptEnd record_attempt_end(Database& db, const RunningCase& run, int exit_code);

/// A summary.json that a solver finished while no driver recorded it: recorded as the result of
/// `attempt` (true); false when there is none, it is cut short, or is not a finished run
/// (is_finished_status of core/run_status.hpp) of case_id.
bool record_left_summary(Database& db, std::int64_t attempt, const std::string& case_id,
                         const std::filesystem::path& run_dir);

}  // namespace boycott::driver
