#pragma once
// What every scene writes the same way: summary.json with the common keys (README.md,
// "Outputs"), timeseries.csv, atomic file replacement.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/run_status.hpp"
#include "core/timers.hpp"

namespace boycott::scenes {

/// True on the rank that writes a run's files: rank 0 under MPI (every rank runs the scene and
/// computes the values, which are global), or the only process.
bool output_rank();

/// Writes `text` to `path` through a temporary file, fsync and rename, so a reader (or a kill)
/// never sees half a file. Only on the output rank (a no-op on the others). A failed write is a
/// StorageError naming the file and the cause; `path` is left as it was.
void write_file_atomic(const std::filesystem::path& path, const std::string& text);

/// Compiler, flags, PETSc version and CPU model of this run (summary.json "build").
nlohmann::json build_info();

/// What a run has spent (over all its attempts where it resumes from checkpoints).
struct RunSpent {
  double wall_s = 0.0;
  double cpu_core_s = 0.0;  ///< NaN when an earlier attempt's was not recorded (older checkpoints)
  /// Each model's wall time, s (ModelTimers::totals), over the attempts since models_from_s.
  std::map<std::string, double> model_wall_s;
  /// Simulated time (s) from which model_wall_s counts: the run's start, or the point where it
  /// resumed from a checkpoint of a build that recorded no model times.
  double models_from_s = 0.0;
};

/// Common summary keys. Scene-specific keys are added to the returned object by the scene.
struct SummaryBase {
  std::string status{kStatusCompleted};  ///< core/run_status.hpp
  double simulated_time_s = 0.0;
  double wall_time_s = 0.0;
  double cpu_time_s = kUnset;   ///< CPU core-seconds over all attempts; kUnset when one's is unknown
  double particle_steps = 0.0;  ///< particles x DEM steps
  double mean_settling_velocity_m_s = kUnset;
  double settling_velocity_stderr_m_s = kUnset;
  void set_spent(const RunSpent& spent) {
    wall_time_s = spent.wall_s;
    cpu_time_s = spent.cpu_core_s;
  }
};
nlohmann::json make_summary(const CaseParams& p, const SummaryBase& s, const ModelTimers& timers);

/// Appends rows to a CSV file with a fixed header; creates it (with the header) when absent.
/// Appending to a file with fewer columns (of an earlier build), it writes only those.
/// Only the output rank writes, each row through to the file at once (readers follow a running
/// case by its last row). A row that could not be written (disk full, I/O error) is a
/// StorageError at the next flush(), naming the file and the cause.
class CsvWriter {
 public:
  CsvWriter(const std::filesystem::path& path, std::vector<std::string> columns, bool append);
  ~CsvWriter();
  void row(const std::vector<double>& values);
  void flush();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

 private:
  std::filesystem::path path_;
  std::FILE* f_ = nullptr;
  std::size_t ncol_;
  int error_ = 0;  ///< errno of the first failed write since opening
};

/// Drops the rows of a CSV file whose first column exceeds t_max (a resumed run repeats nothing
/// and loses nothing: rows written after its checkpoint are computed again). Output rank only.
void truncate_csv_after(const std::filesystem::path& path, double t_max);

/// Wall clock since construction, seconds.
class WallClock {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// CPU seconds (user + system) this process has used, times the MPI ranks (every rank is taken
/// to use what this one does): the core-seconds a run costs, steadier than its wall time on a
/// shared machine and blind to a pause (kill -STOP).
double process_cpu_core_s();

/// What a run has spent over all its attempts: the wall time (s) and CPU core-seconds that its
/// checkpoint carries from the earlier attempts, plus this attempt's since construction.
class RunClock {
 public:
  /// Resuming: what the earlier attempts spent, from the checkpoint.
  void carry(const RunSpent& before) { before_ = before; }
  /// The wall time and CPU core-seconds; the models' wall times are the timers' (a coupled run's
  /// checkpoint takes all three from spent_so_far, scenes/coupled_output.hpp).
  RunSpent spent() const {
    RunSpent s;
    s.wall_s = before_.wall_s + wall_.seconds();
    s.cpu_core_s = before_.cpu_core_s + process_cpu_core_s() - cpu0_;
    return s;
  }

 private:
  WallClock wall_;
  double cpu0_ = process_cpu_core_s();
  RunSpent before_;
};

/// Resuming: the run's clock and its models' timers start from what the earlier attempts spent.
inline void carry_spent(const RunSpent& before, RunClock& clock, ModelTimers& timers) {
  clock.carry(before);
  timers.carry(before.model_wall_s, before.models_from_s);
}

/// When a time-stepping scene writes a checkpoint: on the grid k * every_s of simulated time (so
/// a resumed run keeps the uninterrupted run's schedule), at the end, and when asked to stop.
class CheckpointClock {
 public:
  CheckpointClock(double every_s, double now_s) : every_(every_s), next_(following(now_s)) {}
  /// True when a step that reached t_s is due one (then the next is scheduled).
  bool due(double t_s, double end_s, bool stop) {
    if (t_s < next_ - 1e-12 && !reached_end(t_s, end_s) && !stop) return false;
    next_ = following(t_s);
    return true;
  }

 private:
  double following(double t_s) const { return (std::floor(t_s / every_ + 1e-9) + 1.0) * every_; }
  double every_, next_;
};

/// End of a step of a checkpointed scene: a checkpoint when one is due (the time series flushed
/// first, so that a resumed run finds the rows up to it) and, on a stop request, the summary
/// marked interrupted. Returns true when the scene must leave its loop (exit kExitInterrupted).
template <class WriteCheckpoint>
bool checkpoint_or_stop(bool stop_requested, bool quiet, CheckpointClock& clock, double t_s, double end_s,
                        CsvWriter& csv, WriteCheckpoint&& write_checkpoint, SummaryBase& summary) {
  if (clock.due(t_s, end_s, stop_requested)) {
    csv.flush();
    write_checkpoint();
  }
  if (!stop_requested) return false;
  summary.status = kStatusInterrupted;
  if (!quiet && output_rank())
    std::fprintf(stderr, "stopped at t = %g s after writing a checkpoint; run again to resume\n", t_s);
  return true;
}

/// Output at given simulated times (output.snapshot_times, output.image_times): sorted; on a
/// resumed run those at or before its time are already written.
class OutputTimes {
 public:
  OutputTimes(std::vector<double> times_s, double now_s) : times_(std::move(times_s)) {
    std::sort(times_.begin(), times_.end());
    while (next_ < times_.size() && times_[next_] <= now_s + 1e-12) ++next_;
  }
  std::size_t size() const { return times_.size(); }
  /// Calls write(index, time) for each output time the step that reached t_s passed.
  template <class Write>
  void reached(double t_s, Write&& write) {
    for (; next_ < times_.size() && t_s >= times_[next_] - 1e-12; ++next_) write(next_, times_[next_]);
  }

 private:
  std::vector<double> times_;
  std::size_t next_ = 0;
};

}  // namespace boycott::scenes
