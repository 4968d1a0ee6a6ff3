#pragma once
// What summary.json says about a time average over a scene's averaging window: its error and
// diagnostics, the start-up transient, the time-weighted mean and their warnings. The rules
// themselves are the statistics room's (stats/window_error.hpp, stats/transient.hpp); this file
// writes their results as summary keys and chooses the window from the case (time.average_from).
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "stats/transient.hpp"
#include "stats/window_error.hpp"

namespace boycott::scenes {

/// The summary keys of a time average's error, `prefix` + stderr_m_s, error_m_s (the covering
/// half-width), error_dof (all three from WindowError::err), error_method ("gapped_batch_means",
/// "two_halves", or "two_stage" where time.target_rel_error stopped the run), error_batches,
/// correlation_time_s, correlation_time_upper_s, effective_samples, window_correlation_times (Sokal's
/// diagnostics); null where not available. With `warn` (a finished run), a warning goes to j["warnings"] and
/// stderr when the window holds fewer than ~20 correlation times, saying what the error then rests on. `what`
/// names the quantity. `transient_end_s` (NaN: not known) shapes the advice: average from where the detected
/// transient ends when that is before the window, else run longer.
void report_window_error(nlohmann::json& j, const std::string& prefix, const std::string& what,
                         const stats::WindowError& w, bool warn,
                         double transient_end_s = std::numeric_limits<double>::quiet_NaN());

/// The window a run averages over, from what it collected since start.collect_from_s(): cut at the
/// transient where `start` is automatic (stats::cut_at_transient; where the first stage of the
/// precision target's `plan` cut it, when the plan stopped the run), as collected otherwise. One
/// rule for the scene and for `case summarize`.
stats::ChosenWindow averaging_window(const WindowStart& start, const stats::StepSeries& s,
                                     const std::vector<double>& collected, double now_s,
                                     const stats::TwoStagePlan* plan = nullptr);

/// transient_end_s (stats/transient.hpp: transient_end over the whole series) and average_from_s
/// in `j`; with `warn`, a warning when the transient ends after the window's start and the
/// samples between shift the mean beyond noise. Returns transient_end_s (NaN: no estimate).
double report_transient(nlohmann::json& j, const std::string& what, const stats::StepSeries& s,
                        const std::vector<double>& window, double window_from_s, bool warn);

/// `prefix` + time_weighted_m_s: the window's mean weighted by step length (Eq. 29's mean is over
/// steps; where the CFL limit varies the step they differ), with a warning when the two differ by
/// more than `error` (the covering error of the mean over steps). Null without every step length.
void report_time_weighted(nlohmann::json& j, const std::string& prefix, const std::string& what,
                          const std::vector<double>& window, const stats::StepSeries& s, double error,
                          bool warn);

/// Everything a finished (or stopped) window reports about <<w_p>> from its per-step series:
/// settling_velocity_stderr_m_s and the keys of report_window_error, transient_end_s,
/// average_from_s, the time-weighted mean, settling_velocity_rel_stderr, and their warnings
/// (with `warn`). One place for the scene at its end and for `case summarize` afterwards.
/// `w`: window_error of `window` (computed once by the caller, which needs it too).
void report_settling_statistics(nlohmann::json& j, const stats::StepSeries& s,
                                const std::vector<double>& window, const stats::WindowError& w, bool warn);

/// The texts of the warnings report_settling_statistics may give (their openings), so that a
/// recomputation can replace them.
bool is_settling_statistics_warning(const std::string& text);

/// Appends a warning to j["warnings"] and prints it on stderr (output rank; also under --quiet,
/// which silences progress, so that a study's solver.log keeps it).
void add_warning(nlohmann::json& j, const std::string& text);

}  // namespace boycott::scenes
