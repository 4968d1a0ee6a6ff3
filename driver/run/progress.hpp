#pragma once
// The progress of `study run` on stderr: a line of counts with an ETA, then one line per running
// case with its simulated time and rate; redrawn in place on a terminal, otherwise printed as
// plain lines every `--progress-every` seconds (a Slurm log, `nohup`, `| tee`).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
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
  void draw(const ProgressCounts& counts, const std::vector<RunningCase>& running);
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
};

}  // namespace boycott::driver
