#pragma once
// Scheduling of `study run`: which case runs next (the queue of the cases that the database shows
// neither done nor failed, in study order), how many run at once (--jobs slots, each case on
// --ranks processes), which failed cases run again (--retries, counted over all runs of the
// study), and how a stop signal drains the running cases. A case whose solver hit a storage error
// (exit 74: disk full, I/O error) runs again after a back-off (2, 4, 8 ... s, at most 64 s),
// neither counted against --retries nor set aside; after kStorageFailuresToStop of them in a row
// (any cases) the study stops.
#include <chrono>
#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "driver/run/progress.hpp"
#include "driver/run/solver_process.hpp"
#include "driver/store/database.hpp"
#include "driver/store/store.hpp"
#include "driver/study/study.hpp"

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
  /// > 0: this many wall seconds after `study run` started, every running case is asked to
  /// checkpoint and stop, as by a SIGTERM to the driver, and no case starts (a session or a
  /// machine booked until a given hour: nothing run is lost, the same command resumes).
  double stop_after_s = 0.0;
  /// When stop_after_s runs out: set by study_run at its start (steady clock).
  std::optional<std::chrono::steady_clock::time_point> stop_at;
};

class Scheduler {
 public:
  /// Queues the cases of `study` that `states` (case_states of db) shows neither done nor failed,
  /// those stopped part-way (interrupted, or an attempt left open) first; each runs as `solver`
  /// in <runs_root>/<case_id>/. study and opt must outlive the scheduler.
  Scheduler(Database& db, const Study& study, const std::vector<CaseState>& states,
            const StudyRunOptions& opt, std::filesystem::path runs_root, std::vector<std::string> solver);

  /// Runs cases until the queue is empty, or after a stop signal or opt.stop_at (or too many
  /// storage errors in a row) until the running cases have checkpointed and exited; true when a
  /// stop ended it.
  bool run();
  /// Why the study stopped for storage errors; empty when it did not.
  const std::string& storage_stop() const { return storage_stop_; }

  static constexpr int kStorageFailuresToStop = 5;
  /// The plan's estimate per case id, for the progress display's ETA.
  void set_plan(const std::map<std::string, PlannedCase>& cases) { progress_.set_plan(cases); }

 private:
  /// Starts the case, or records it without running it when its result is already there; false
  /// while another process holds its run folder.
  bool start(const StudyCase* c);
  /// Records how a solver ended and decides whether its case runs again.
  void finish(const RunningCase& run, int exit_code);
  void reap(const SolverExit& exited);
  void stop_all();
  ProgressCounts counts() const;

  Database& db_;
  const StudyRunOptions& opt_;
  std::filesystem::path runs_root_;
  std::vector<std::string> solver_;
  std::deque<const StudyCase*> queue_;
  std::map<std::string, int> failures_;  ///< failed attempts by case id, over all runs of the study
  int done_ = 0;
  int failed_ = 0;
  std::vector<RunningCase> running_;
  /// Cases whose solver hit a storage error, each with the time it may run again.
  std::vector<std::pair<std::chrono::steady_clock::time_point, const StudyCase*>> backing_off_;
  int storage_failures_in_a_row_ = 0;
  std::string storage_stop_;
  bool stopping_ = false;
  ProgressDisplay progress_;
};

}  // namespace boycott::driver
