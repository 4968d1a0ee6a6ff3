#pragma once
// The error of a time average over a scene's averaging window, from the whole per-step series
// (core/statistics.hpp: integrated autocorrelation time, Sokal's window), as summary.json reports
// it; and time.target_rel_error, which ends a run once that error is small enough.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/statistics.hpp"

namespace boycott::scenes {

/// The error of the mean of `series`, the per-step samples over [window_from_s, now_s]: Sokal's
/// estimate and its diagnostics (e), and the error the run reports (err; core/statistics.hpp,
/// MeanError): batch means, as many batches as e's count of correlation times allows, the two
/// halves at least; Sokal's own where time.target_rel_error stopped the run (`stopped_by_target`),
/// since the stop was judged on it and its coverage measured under that stop (PrecisionTarget).
struct WindowError {
  AutocorrelationError e;
  MeanError err;
  double from_s = 0.0;    ///< window_from_s
  double window_s = 0.0;  ///< now_s - window_from_s
  double sample_s = 0.0;  ///< window_s / samples, the mean step (s)
  double correlation_time_s() const { return e.tau_int * sample_s; }
  double correlation_time_upper_s() const { return e.tau_int_upper * sample_s; }
};
WindowError window_error(const std::vector<double>& series, double window_from_s, double now_s,
                         bool stopped_by_target = false);

/// The summary keys of a time average's error, `prefix` + stderr_m_s, error_m_s (the covering
/// half-width), error_dof (all three from WindowError::err), error_method ("batch_means"
/// or "two_halves"), error_batches, correlation_time_s, correlation_time_upper_s, effective_samples,
/// window_correlation_times (Sokal's diagnostics); null where not available. With `warn` (a
/// finished run), a warning goes to j["warnings"] and stderr when the window holds fewer than ~20
/// correlation times, saying what the error then rests on. `what` names the quantity.
/// `transient_end_s` (NaN: not known) shapes the advice: average from where the detected transient
/// ends when that is before the window, else run longer.
void report_window_error(nlohmann::json& j, const std::string& prefix, const std::string& what,
                         const WindowError& w, bool warn,
                         double transient_end_s = std::numeric_limits<double>::quiet_NaN());

/// The per-step series behind a time average: the samples before the averaging window (kept for
/// the detection of the start-up transient) and in it, each with its step length (s). Runs
/// resumed from checkpoints of builds that kept no step lengths or no samples before the window
/// have them only from the resume on (`before_whole`, `dt_whole` false).
struct StepSeries {
  std::vector<double> before, before_dt, window_dt;
  bool before_whole = true, dt_whole = true;
};

/// A window the run chose itself (time.average_from = "auto"): `window` holds every sample since
/// `collected_from_s` (its step lengths in s.window_dt); it is cut where transient_end finds the
/// start-up transient over, the samples before the cut joining s.before. No estimate (a series too
/// short for one): no cut.
struct ChosenWindow {
  StepSeries steps;
  std::vector<double> window;
  double from_s = 0.0;
};
ChosenWindow cut_at_transient(const StepSeries& s, const std::vector<double>& window, double collected_from_s,
                              double now_s);
/// The window a run averages over, from what it collected since start.collect_from_s(): cut at the
/// transient where `start` is automatic, as collected otherwise. One rule for the scene and for
/// `case summarize`.
ChosenWindow averaging_window(const WindowStart& start, const StepSeries& s,
                              const std::vector<double>& collected, double now_s);

/// transient_end_s (core/statistics.hpp: transient_end over the whole series) and average_from_s
/// in `j`; with `warn`, a warning when the transient ends after the window's start and the
/// samples between shift the mean beyond noise. Returns transient_end_s (NaN: no estimate).
double report_transient(nlohmann::json& j, const std::string& what, const StepSeries& s,
                        const std::vector<double>& window, double window_from_s, bool warn);

/// `prefix` + time_weighted_m_s: the window's mean weighted by step length (Eq. 29's mean is over
/// steps; where the CFL limit varies the step they differ), with a warning when the two differ by
/// more than `error` (the covering error of the mean over steps). Null without every step length.
void report_time_weighted(nlohmann::json& j, const std::string& prefix, const std::string& what,
                          const std::vector<double>& window, const StepSeries& s, double error, bool warn);

/// Everything a finished (or stopped) window reports about <<w_p>> from its per-step series:
/// settling_velocity_stderr_m_s and the keys of report_window_error, transient_end_s,
/// average_from_s, the time-weighted mean, settling_velocity_rel_stderr, and their warnings
/// (with `warn`). One place for the scene at its end and for `case summarize` afterwards.
/// `w`: window_error of `window` (computed once by the caller, which needs it too).
void report_settling_statistics(nlohmann::json& j, const StepSeries& s, const std::vector<double>& window,
                                const WindowError& w, bool warn);

/// The texts of the warnings report_settling_statistics may give (their openings), so that a
/// recomputation can replace them.
bool is_settling_statistics_warning(const std::string& text);

/// Appends a warning to j["warnings"] and prints it on stderr (output rank; also under --quiet,
/// which silences progress, so that a study's solver.log keeps it).
void add_warning(nlohmann::json& j, const std::string& text);

/// time.target_rel_error: a run may stop once Sokal's covering error of <<w_p>> over its window
/// (AutocorrelationError::covering_error; the error_m_s of a run it stops) is below
/// target |<<w_p>>|, the window holds at least kMinCorrelationTimes correlation times
/// (counted conservatively, AutocorrelationError::correlation_times), and the target has been
/// met at every check over at least kConfirmCorrelationTimes correlation times and over
/// kConfirmWindowFraction of the window it was first met at (two checks that far apart, none
/// failing between). Confirming over 10 correlation times alone let the error at the stop cover
/// 0.65 (the stop came where tau was under-estimated); over 30 % of the window it covers
/// 0.665-0.677 at five targets where the target decides the stop, and 0.658-0.659 where the
/// floor of kMinCorrelationTimes does (10 000 series each), for runs ~25 % longer
/// (docs/validation.md, "Error bars"). Not batch means, which a run that ends at time.end
/// reports: their few degrees of freedom at these lengths make the error noisy, the stop comes
/// where it dipped, and it then covers 0.62 (0.65 if Sokal's judges the stop and batch means are
/// reported). Checks fall on a
/// fixed schedule of sample counts, so a resumed run checks where the uninterrupted one did; the state goes
/// into checkpoints.
class PrecisionTarget {
 public:
  static constexpr double kMinCorrelationTimes = 50.0;
  static constexpr double kConfirmCorrelationTimes = 10.0;
  static constexpr double kConfirmWindowFraction = 0.3;
  static constexpr std::int64_t kFirstCheck = 50;  ///< samples

  /// target: time.target_rel_error (NaN: no target, never stops). cut_transient: the window is
  /// the run's own choice (time.average_from = "auto"): each check judges the series from where
  /// its start-up transient is detected to end.
  explicit PrecisionTarget(double target, bool cut_transient = false)
      : target_(target), cut_transient_(cut_transient) {}
  bool active() const { return target_ == target_; }
  /// After a sample was added to `series`: true when the run may stop now.
  bool reached(const std::vector<double>& series, double window_from_s, double now_s);
  /// The last check's relative error (NaN before the first).
  double last_rel_error() const { return last_rel_error_; }

  // State, for checkpoints.
  std::int64_t next_check_ = kFirstCheck;
  double met_since_s_ = -1.0;  ///< time of the first check of the streak; < 0: not met

 private:
  double target_;
  bool cut_transient_;
  double last_rel_error_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace boycott::scenes
