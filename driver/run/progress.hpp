#pragma once
// The progress of `study run` on stderr: a line of counts with an ETA, then one line per running
// case with its simulated time and rate; redrawn in place on a terminal, otherwise printed as
// plain lines every `--progress-every` seconds (a Slurm log, `nohup`, `| tee`).
#include <chrono>
#include <cstddef>
#include <deque>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
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
  /// The pending cases' ids where known (the ETA prices each by its plan); pending may count more.
  std::vector<std::string> pending_ids;
};

/// The plan's estimate of a case's rest (`study run`'s first line): wall_s on the study's ranks
/// for the simulated time from from_s to end_s.
struct PlannedCase {
  double wall_s = 0.0;
  double from_s = 0.0;
  double end_s = 0.0;
  /// Planned wall seconds per simulated second; NaN where the rest spans no simulated time.
  double wall_s_per_sim_s() const;
};

class ProgressDisplay {
 public:
  /// live: redrawn in place (a terminal); else plain lines every plain_every_s seconds (<= 0:
  /// nothing).
  ProgressDisplay(std::string study, int jobs, bool live, double plain_every_s);

  /// A case finished in this run after `wall_s` seconds, having run from simulated time from_s:
  /// the time per case of the pending cases the plan does not price, and, measured against the
  /// plan, how fast the cases run against it.
  void add_finished_case(const std::string& id, double wall_s, double from_s);
  /// The plan's estimate per case id (the line `study run` prints first), so that the first ETA
  /// is the plan's. The ETA prices each pending case by its own estimate (a study's cases differ
  /// several-fold: a 405 000-particle case against a 120 000 one) times the mean ratio of the
  /// measured to the planned wall time per simulated second over the cases running or finished
  /// in this run; a case stopped part-way only for the simulated time it has left.
  void set_plan(const std::map<std::string, PlannedCase>& cases);

  /// Replaces the lines drawn last.
  void draw(const ProgressCounts& counts, const std::vector<RunningCase>& running) {
    draw_at(counts, running, std::chrono::steady_clock::now());
  }
  /// draw() at the time `now` (a test passes its own: no test may judge wall time). A running
  /// case's rate is its recent one (RecentRate, sampled at each draw from its start).
  void draw_at(const ProgressCounts& counts, const std::vector<RunningCase>& running,
               std::chrono::steady_clock::time_point now);
  /// draw() with counts(), at most twice a second live, else every plain_every_s (counts() is
  /// asked only then: it lists every pending case, and the scheduler polls every 20 ms).
  void redraw_if_due(const std::function<ProgressCounts()>& counts, const std::vector<RunningCase>& running);

 private:
  std::string study_;
  int jobs_;
  bool live_;
  double plain_every_s_;
  std::vector<double> finished_wall_s_;
  std::unordered_map<std::string, PlannedCase> plan_;  ///< looked up for every pending case at each draw
  double planned_case_wall_s_ = std::numeric_limits<double>::quiet_NaN();  ///< the plan's mean
  /// Measured over planned wall time per simulated second, by id, of each case that ran in this
  /// run: its whole attempt once finished, else its recent rate when last seen running.
  std::map<std::string, double> speed_ratios_;
  std::map<std::string, double> last_t_s_;  ///< by id: where each case was when last seen running
  int printed_lines_ = 0;
  std::chrono::steady_clock::time_point last_draw_;
  std::map<std::string, RecentRate> rates_;  ///< by run folder, of the cases running now
};

}  // namespace boycott::driver
