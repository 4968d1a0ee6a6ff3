#pragma once
// The status a run's summary.json carries, one vocabulary for the solver, the driver and the
// driver's test double; with the exit codes of error.hpp.
#include <string_view>

namespace boycott {

inline constexpr std::string_view kStatusCompleted = "completed";  ///< reached time.end (exit 0)
inline constexpr std::string_view kStatusConverged =
    "converged";  ///< met time.target_rel_error first (exit 0)
inline constexpr std::string_view kStatusInterrupted =
    "interrupted";                                           ///< stopped after a checkpoint (exit 75)
inline constexpr std::string_view kStatusFailed = "failed";  ///< stopped by an error (exit 1-4, 74)

/// Round-off allowed where a run's time meets time.end, s: time advances by sums of steps and can
/// fall short of a value it has reached by round-off; 1e-12 s is far below any step.
inline constexpr double kEndToleranceS = 1e-12;

/// Whether a run at t_s has reached time.end = end_s: the one definition the scenes' time loops,
/// the resume check and the study database (its SQL function reached_end) all use.
inline bool reached_end(double t_s, double end_s) {
  return t_s >= end_s - kEndToleranceS;
}

/// A run with a result to record: completed or converged.
inline bool is_finished_status(std::string_view s) {
  return s == kStatusCompleted || s == kStatusConverged;
}

}  // namespace boycott
