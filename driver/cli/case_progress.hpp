#pragma once
// The progress of `case run` on stderr (rank 0): simulated time, rate, ETA and the scene's main
// quantity so far; one line redrawn in place on a terminal, otherwise a plain line every
// `--progress-every` seconds, so that a Slurm log or `nohup` shows a long run is alive.
#include <chrono>
#include <functional>
#include <string>

#include "driver/run/progress.hpp"

namespace boycott::driver {

class CaseProgress {
 public:
  using Clock = std::chrono::steady_clock;
  /// Where the lines go and what time it is: a test passes its own (no test may judge wall time).
  struct Io {
    std::function<Clock::time_point()> now = [] { return Clock::now(); };
    std::function<void(const std::string&)> write;  ///< default: stderr, flushed
  };
  /// end_s: time.end (s); live: redraw one line (a terminal); every_s: seconds between plain lines.
  CaseProgress(double end_s, bool live, double every_s);
  CaseProgress(double end_s, bool live, double every_s, Io io);
  /// The scene's note for the next line (e.g. "mean_wp_m_s -0.0816").
  void note(const std::string& text) { note_ = text; }
  /// The run reached simulated time t_s; prints when a line is due.
  void at(double t_s);
  /// After the run: ends the live line with the run's rate and wall time (no ETA: it is over).
  void finish();

 private:
  std::string line(double t_s, bool finished) const;
  void write(const std::string& s) const;
  double seconds(Clock::time_point a, Clock::time_point b) const {
    return std::chrono::duration<double>(b - a).count();
  }

  double end_s_;
  bool live_;
  double every_s_;
  Io io_;
  std::string note_;
  bool started_ = false, on_line_ = false;
  double t0_s_ = 0.0, t_last_s_ = 0.0;
  Clock::time_point wall0_, last_print_, now_;
  /// The ETA extrapolates the recent rate, not the whole run's.
  RecentRate recent_;
};

}  // namespace boycott::driver
