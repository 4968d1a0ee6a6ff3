#include "driver/cli/case_progress.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "driver/run/progress.hpp"

namespace boycott::driver {

CaseProgress::CaseProgress(double end_s, bool live, double every_s)
    : CaseProgress(end_s, live, every_s, Io{}) {}

CaseProgress::CaseProgress(double end_s, bool live, double every_s, Io io)
    : end_s_(end_s), live_(live), every_s_(every_s), io_(std::move(io)) {
  wall0_ = last_print_ = now_ = io_.now();
}

void CaseProgress::write(const std::string& s) const {
  if (io_.write) return io_.write(s);
  std::fputs(s.c_str(), stderr);
  std::fflush(stderr);
}

std::string CaseProgress::line(double t_s, bool finished) const {
  std::string s = fmt::format("t = {:.4g} / {:g} s ({:.0f} %)", t_s, end_s_, 100.0 * t_s / end_s_);
  // The rate from the first report on: a resumed run starts late, and its set-up is not the rate.
  const double wall_s = seconds(wall0_, now_), sim_s = t_s - t0_s_;
  if (sim_s > 0 && finished) {
    s += fmt::format(", {:.3g} wall s per simulated s, {} wall", wall_s / sim_s, eta_text(wall_s));
  } else if (sim_s > 0) {
    const double recent = recent_.wall_s_per_sim_s(now_, t_s);
    const double rate = std::isfinite(recent) ? recent : wall_s / sim_s;
    s += fmt::format(", {:.3g} wall s per simulated s, ETA {}", rate, eta_text(rate * (end_s_ - t_s)));
  }
  if (!note_.empty()) s += ", " + note_;
  return s;
}

void CaseProgress::at(double t_s) {
  t_last_s_ = t_s;
  now_ = io_.now();
  if (!started_) {
    started_ = true;
    t0_s_ = t_s;
    wall0_ = last_print_ = now_;
    recent_ = RecentRate{};
    recent_.add(now_, t_s);
    return;
  }
  recent_.add(now_, t_s);
  const double since = seconds(last_print_, now_);
  if (live_ && since >= 0.5) {
    write(fmt::format("\r{}\033[K", line(t_s, false)));
    on_line_ = true;
    last_print_ = now_;
  } else if (!live_ && every_s_ > 0 && since >= every_s_) {
    write(fmt::format("progress: {}\n", line(t_s, false)));
    last_print_ = now_;
  }
}

void CaseProgress::finish() {
  now_ = io_.now();
  if (live_ && on_line_) write(fmt::format("\r{}\033[K\n", line(t_last_s_, true)));
  on_line_ = false;
}

}  // namespace boycott::driver
