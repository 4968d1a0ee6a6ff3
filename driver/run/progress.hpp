#pragma once
// The progress of `study run` on stderr: a line of counts with an ETA, then one line per running
// case with its simulated time and rate; redrawn in place on a terminal, otherwise printed as
// plain lines every `--progress-every` seconds (a Slurm log, `nohup`, `| tee`).
#include <chrono>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "driver/run/solver_process.hpp"

namespace boycott::driver {

/// A remaining time for a progress line: "42s", "3m07s", "2h05m"; "?" when unknown.
std::string eta_text(double seconds);
/// "1 case", "2 cases": a count with its noun, plural by an s.
std::string count_of(long long n, const std::string& noun);

/// Simulated time of a running case: first column of the last line of <run_dir>/timeseries.csv;
/// 0 before the solver wrote one.
double simulated_time_s(const std::filesystem::path& run_dir);
/// The value in the column named `column` of the last line of <run_dir>/timeseries.csv (its
/// header names the columns); NaN where the file, the column or a number there is missing.
double last_row_value(const std::filesystem::path& run_dir, const std::string& column);

/// A run's rate over its recent past: (wall time, simulated time) samples at least
/// kSampleEveryS apart, kept back to the last one older than max(kRecentMinS, kRecentFraction x
/// the wall time since the first sample), so that the rate is the recent one, not the whole
/// run's: the first steps of a settling run are the cheapest, and a run paused for a while (a
/// campaign stopped for a benchmark) counts the pause only until it leaves that window.
class RecentRate {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr double kRecentMinS = 10.0, kRecentFraction = 0.25, kSampleEveryS = 0.5;
  /// The run is at simulated time t_s (s) at `now`.
  void add(Clock::time_point now, double t_s);
  /// Wall seconds per simulated second from the oldest kept sample to (now, t_s); NaN while
  /// that spans no simulated time.
  double wall_s_per_sim_s(Clock::time_point now, double t_s) const;
  bool empty() const { return samples_.empty(); }

 private:
  std::deque<std::pair<Clock::time_point, double>> samples_;
  Clock::time_point first_;
};

/// What the counts line shows.
struct ProgressCounts {
  int done = 0;
  int failed = 0;
  std::size_t pending = 0;
  bool stopping = false;
};

class ProgressDisplay {
 public:
  /// live: redrawn in place (a terminal); else plain lines every plain_every_s seconds (<= 0:
  /// nothing).
  ProgressDisplay(std::string study, int jobs, bool live, double plain_every_s);

  /// A case finished in this run after `wall_s` seconds: the ETA's time per case from now on.
  void add_finished_case(double wall_s) { finished_wall_s_.push_back(wall_s); }
  /// The plan's wall time per case (the line `study run` prints first): the ETA's time per case
  /// until cases report a rate or finish, so that the first ETA is the plan's.
  void set_planned_case_wall_s(double wall_s) { planned_case_wall_s_ = wall_s; }

  /// Replaces the lines drawn last.
  void draw(const ProgressCounts& counts, const std::vector<RunningCase>& running) {
    draw_at(counts, running, std::chrono::steady_clock::now());
  }
  /// draw() at the time `now` (a test passes its own: no test may judge wall time). A running
  /// case's rate is its recent one (RecentRate, sampled at each draw from its start).
  void draw_at(const ProgressCounts& counts, const std::vector<RunningCase>& running,
               std::chrono::steady_clock::time_point now);
  /// draw(), at most twice a second live, else every plain_every_s.
  void redraw_if_due(const ProgressCounts& counts, const std::vector<RunningCase>& running);

 private:
  std::string study_;
  int jobs_;
  bool live_;
  double plain_every_s_;
  std::vector<double> finished_wall_s_;
  double planned_case_wall_s_ = std::numeric_limits<double>::quiet_NaN();
  int printed_lines_ = 0;
  std::chrono::steady_clock::time_point last_draw_;
  std::map<std::string, RecentRate> rates_;  ///< by run folder, of the cases running now
};

}  // namespace boycott::driver
