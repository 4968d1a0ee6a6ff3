#pragma once
// The start-up transient of a series: where it ends, whether it biases a mean, and a window cut
// where it ends (time.average_from = "auto").
#include <cstdint>
#include <vector>

namespace boycott::stats {

/// Where a series' start-up transient ends, by a test that a stationary series passes: the
/// series is cut into segments of n / (2 kSegments) samples; the second half (the reference,
/// taken as stationary) holds kSegments of them, and the first half's segments are compared with
/// it in turn: a segment's mean against the reference's mean, within Student's t (at kSegments - 1
/// degrees of freedom, two-sided kFalseAlarm) times the scatter of the reference's own segment
/// means, and its spread within kSpreadFactor times the reference's variance (a swing that
/// averages out, as stages I and II of a settling run can, shows in the spread). The transient
/// is detected to end after the last segment that fails before two that pass (`detected`); the
/// window is cut kGuardSpans correlation spans of the reference further in (the
/// upper end of AutocorrelationError::span; at most half the series): a decay that a segment can
/// no longer tell from noise still biases a mean over many segments, and a decay as slow as the
/// series' own memory is what the segments see least.
///
/// Why the scatter of the reference's segments and not a correlation time: it is the variance of
/// a segment's mean whatever the correlation inside a segment, an oscillation's part-periods and
/// a slow part included, where 2 s^2 tau_int / len is not (an oscillation's tau_int can be far
/// below its envelope's decay time, or have no estimate at all: such series went uncut).
/// Why a test and not an optimum: the rule before issue 61 cut where the effective samples of what
/// followed were most (Chodera 2016) or MSER least (White 1997); each chooses the tail whose
/// batches happen to agree, so its error is small by selection: after such a cut the error
/// covered 0.52-0.64 on stationary series, most of which it cut. A test cuts a stationary series
/// only when a segment fails by chance (~5 % of series), and then mostly a segment or two; the
/// error of what is kept is the ordinary one (docs/validation.md, "Transients").
/// 20 segments and 5 spans: a swing that ends at 1.4 % of the window costs < 10 % of it, a strong
/// fast decay on white noise is cut where it has fallen to the noise (tests TransientEnd.*,
/// TransientReport.*). A guard of 3.5 times the detected end (or 10 segments and 5 times) cut
/// more of a weak slow decay under a two-scale or oscillating series, but threw away a quarter of
/// a window whose transient is short and cut such a decay at twice the time it had fallen to the
/// noise; 1.5 times plus 5 spans still cut it 20 % too late where the steps are uneven.
struct TransientEnd {
  std::int64_t start = 0;     ///< first sample of the stationary part: the cut
  std::int64_t detected = 0;  ///< where the segments stop differing from the reference
  bool estimated = false;     ///< false: no test (fewer than 16 samples, or a constant reference)
  static constexpr int kSegments = 20;
  static constexpr double kFalseAlarm = 0.02;
  static constexpr double kSpreadFactor = 4.0;
  static constexpr double kGuardSpans = 5.0;
};
TransientEnd transient_end(const std::vector<double>& x);

/// Whether the samples between `from` and `start` (where the transient is detected to end,
/// TransientEnd::detected, from < start) are a transient that matters rather than noise: their
/// mean differs from the rest's by more than kTransientSignificance standard errors of the
/// difference, the head's error taken as if it were more of the stationary part (its own would be
/// inflated by a trend). Judged up to `detected`, not the cut: the guard beyond it would dilute
/// the head with stationary samples. 2.25 rather than 2 because the end was found where the head
/// looks unlike the rest: on stationary AR(1) series of 200 correlation times it fires for 2 %, on
/// a transient that biases the mean by one standard error for 95 % (tests TransientEnd.*).
bool transient_biases_mean(const std::vector<double>& x, std::int64_t from, std::int64_t start);
inline constexpr double kTransientSignificance = 2.25;

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
/// The same window cut at sample k (0 <= k <= window.size()): where a precision target's first
/// stage fixed it (TwoStagePlan::cut).
ChosenWindow cut_window_at(const StepSeries& s, const std::vector<double>& window, double collected_from_s,
                           double now_s, std::int64_t k);

}  // namespace boycott::stats
