#pragma once
// The live display of `study run` (only when stdout is a terminal): a line of counts with an ETA,
// then one line per running case with its simulated time and rate, redrawn in place.
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "driver/solver_process.hpp"

namespace boycott::driver {

/// Simulated time of a running case: first column of the last line of <run_dir>/timeseries.csv;
/// 0 before the solver wrote one.
double simulated_time_s(const std::filesystem::path& run_dir);

/// What the counts line shows.
struct ProgressCounts {
  int done = 0;
  int failed = 0;
  std::size_t pending = 0;
  bool stopping = false;
};

class ProgressDisplay {
 public:
  /// enabled false: draw() prints nothing.
  ProgressDisplay(std::string study, int jobs, bool enabled);

  /// A case finished in this run after `wall_s` seconds: the ETA's time per case from now on.
  void add_finished_case(double wall_s) { finished_wall_s_.push_back(wall_s); }

  /// Replaces the lines drawn last.
  void draw(const ProgressCounts& counts, const std::vector<RunningCase>& running);
  /// draw(), at most twice a second.
  void redraw_if_due(const ProgressCounts& counts, const std::vector<RunningCase>& running);

 private:
  std::string study_;
  int jobs_;
  bool enabled_;
  std::vector<double> finished_wall_s_;
  int printed_lines_ = 0;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace boycott::driver
