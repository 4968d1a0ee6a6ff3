#pragma once
// The progress of `case run` on stderr (rank 0): simulated time, rate, ETA and the scene's main
// quantity so far; one line redrawn in place on a terminal, otherwise a plain line every
// `--progress-every` seconds, so that a Slurm log or `nohup` shows a long run is alive.
#include <chrono>
#include <string>

namespace boycott::driver {

class CaseProgress {
 public:
  /// end_s: time.end (s); live: redraw one line (a terminal); every_s: seconds between plain lines.
  CaseProgress(double end_s, bool live, double every_s);
  /// The scene's note for the next line (e.g. "mean_wp_m_s -0.0816").
  void note(const std::string& text) { note_ = text; }
  /// The run reached simulated time t_s; prints when a line is due.
  void at(double t_s);
  /// After the run: ends the live line (or prints the last plain one).
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string line(double t_s) const;

  double end_s_;
  bool live_;
  double every_s_;
  std::string note_;
  bool started_ = false, printed_ = false;
  double t0_s_ = 0.0, t_last_s_ = 0.0;
  Clock::time_point wall0_, last_print_;
};

}  // namespace boycott::driver
