#include "driver/case_progress.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "driver/progress.hpp"

namespace boycott::driver {

CaseProgress::CaseProgress(double end_s, bool live, double every_s)
    : end_s_(end_s), live_(live), every_s_(every_s), wall0_(Clock::now()), last_print_(Clock::now()) {}

std::string CaseProgress::line(double t_s) const {
  // The rate from the first report on: a resumed run starts late, and its set-up is not the rate.
  const double wall_s = std::chrono::duration<double>(Clock::now() - wall0_).count();
  const double sim_s = t_s - t0_s_;
  const double wall_per_sim = sim_s > 0 ? wall_s / sim_s : NAN;
  std::string s = fmt::format("t = {:.4g} / {:g} s ({:.0f} %)", t_s, end_s_, 100.0 * t_s / end_s_);
  if (std::isfinite(wall_per_sim))
    s += fmt::format(", {:.3g} wall s per simulated s, ETA {}", wall_per_sim,
                     eta_text(wall_per_sim * (end_s_ - t_s)));
  if (!note_.empty()) s += ", " + note_;
  return s;
}

void CaseProgress::at(double t_s) {
  t_last_s_ = t_s;
  if (!started_) {
    started_ = true;
    t0_s_ = t_s;
    wall0_ = Clock::now();
    return;
  }
  const double since = std::chrono::duration<double>(Clock::now() - last_print_).count();
  if (live_ && since >= 0.5) {
    std::fprintf(stderr, "\r%s\033[K", line(t_s).c_str());
    std::fflush(stderr);
    printed_ = true;
    last_print_ = Clock::now();
  } else if (!live_ && every_s_ > 0 && since >= every_s_) {
    std::fprintf(stderr, "progress: %s\n", line(t_s).c_str());
    std::fflush(stderr);
    last_print_ = Clock::now();
  }
}

void CaseProgress::finish() {
  if (live_ && printed_) std::fprintf(stderr, "\r%s\033[K\n", line(t_last_s_).c_str());
}

}  // namespace boycott::driver
