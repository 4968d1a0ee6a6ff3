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
/// is detected to end after the last segment that fails before two that pass (`detected`). The
/// window is cut at the later of two guards beyond it: kGuardSpans correlation spans of the
/// reference (the upper end of AutocorrelationError::span), and where an exponential fitted to
/// the first half's segment means (its decay time at the slow end of its profile interval) says
/// the transient's rest biases the kept mean by less than kResidualBias standard errors; at most
/// half the series. A decay that a segment can no longer tell from noise still biases a mean over
/// many segments: the spans cover a decay as slow as the series' own memory, the fit one slower
/// than that (a slow part or an oscillation's envelope under fast noise, whose transient the
/// spans cut too early). Where no segment fails, the fit alone may still show a decay (it pools
/// the segments, as a matched filter does): the window is then cut where the fit says, and
/// `detected` is that cut. A transient that biases the mean by one standard error is seen so in
/// 1.3-1.4 times as many series as by the segments alone (docs/validation.md, "Transients").
///
/// Why the scatter of the reference's segments and not a correlation time: it is the variance of
/// a segment's mean whatever the correlation inside a segment, an oscillation's part-periods and
/// a slow part included, where 2 s^2 tau_int / len is not (an oscillation's tau_int can be far
/// below its envelope's decay time, or have no estimate at all: such series went uncut).
/// Why a test and not an optimum: the rule before issue 61 cut where the effective samples of what
/// followed were most (Chodera 2016) or MSER least (White 1997); each chooses the tail whose
/// batches happen to agree, so its error is small by selection: after such a cut the error
/// covered 0.52-0.64 on stationary series, most of which it cut. A test cuts a stationary series
/// only when a segment or the fit fails by chance (4-9 % of series), and then mostly a segment
/// or two; the error of what is kept is the ordinary one (docs/validation.md, "Transients").
/// 20 segments and 5 spans: a swing that ends at 1.4 % of the window costs < 10 % of it, a strong
/// fast decay on white noise is cut where it has fallen to the noise (tests TransientEnd.*,
/// TransientReport.*). A guard of 3.5 times the detected end instead of the fit cut a weak slow
/// decay less far (0.86 and 0.47 of two-scale and oscillating series left unbiased, against 0.99
/// and 0.91 with the fit), threw away a quarter of a window whose transient is short and cut a
/// fast decay at twice the time it had fallen to the noise.
/// kResidualBias = 0.25: an interval of one standard error about a mean biased by that much
/// still holds it Phi(0.75) - Phi(-1.25) = 0.667 of the time, leaving the estimator's own
/// shortfall room above 0.65 (0.35, where that figure is 0.653, left the two-scale family at 0.645).
/// kDecayProfile = 2.71: chi^2 with one degree of freedom at 90 %, the segment means' residuals
/// being in units of a segment mean's variance.
struct TransientEnd {
  std::int64_t start = 0;     ///< first sample of the stationary part: the cut
  std::int64_t detected = 0;  ///< where the segments stop differing from the reference
  bool estimated = false;     ///< false: no test (fewer than 16 samples, or a constant reference)
  static constexpr int kSegments = 20;
  static constexpr double kFalseAlarm = 0.02;
  static constexpr double kSpreadFactor = 4.0;
  static constexpr double kGuardSpans = 5.0;
  static constexpr double kResidualBias = 0.25;
  static constexpr double kDecayProfile = 2.71;
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
