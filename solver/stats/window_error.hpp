#pragma once
// The error of a time average over its averaging window: the rule a run reports it by (MeanError:
// gapped batch means, the two halves at least, or the two-stage error where a precision target
// stopped the run) and the window's error with its diagnostics (WindowError), as summary.json
// states them (scenes/summary_statistics.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "stats/autocorrelation.hpp"

namespace boycott::stats {

/// The error one run reports for the mean of its series, and what it rests on: batch means with
/// Student's t at k - 1 degrees of freedom (Schmeiser, Oper. Res. 30, 556 (1982); Law & Kelton).
/// The series is cut into k batches of equal length with gaps between them, and the standard error
/// is sd(batch means) / sqrt(k). Batch means are nearly independent when each batch is much longer
/// than the correlation time: neighbours correlate through the samples either side of their
/// border (by ~sum_t t rho(t) / (2 tau_int b) for batches of b samples: tau_int / (2 b) for an
/// exponential decay), so one correlation time (the upper end of its estimate) is left out at each
/// border, at most a tenth of the series (kGapFraction; a tenth too where no count could be made).
/// k is as many batches of kCorrelationTimesPerBatch correlation times as the conservative count
/// (AutocorrelationError::batch_count: of tau_int, or of correlation spans where those are fewer,
/// as in an oscillation whose lobes cancel in tau_int) allows, two at least and kMaxBatches at most: the two
/// halves of the series (basis two_halves, 1 degree of freedom, t = 1.84) in runs of fewer than 120
/// counted correlation times, where no count could be made, and always in short series.
///
/// Why at most 8 batches: the count comes from Sokal's tau_int, which a slow part of small weight
/// fools (0.7-0.9 of the true one on sums of AR(1) processes whose times are 3-30 apart), and even
/// a true tau_int says nothing of the time over which neighbouring batches correlate, which is the
/// slow part's (for an oscillation, its envelope's decay time). Batches of 20 estimated correlation
/// times are then a few slow ones long: neighbours correlate, and the error falls short on such
/// series (without the cap 0.652-0.658 at 50-200 slowest times, with it 0.658-0.676), while on an
/// oscillation whose tau_int is small many short batches carry part-periods that make the error
/// too wide (0.79, counted by tau_int; 0.69 by spans). A cap lets the
/// batches grow with the window, so that whatever the data hide, the correlation of neighbours
/// falls as 1 / N; its price is small: t_7 times the scatter of an 8-batch error is 1.04 true
/// standard errors on average, against 1.00 with many batches (docs/validation.md, "One run").
///
/// Why 40 counted correlation times a batch, not 20: the same slow part that fools the count makes
/// neighbouring batches of 20 correlate, so the batches agree more than independent ones would. At
/// 20 the two-scale family covered 0.658 at 50 slowest times, and after an automatic cut that
/// missed a decay worth 1 standard error 0.630 (two scales) and 0.642 (oscillation); at 40 they
/// cover 0.672, 0.655 and 0.669, and every family figure lies in 0.65-0.71 (docs/validation.md,
/// "Series that are not AR(1)"). The price falls on series with one time scale, which 20 already
/// served: AR(1) keeps the two halves up to 120 counted times, and its mean half-width is 1.47 true
/// standard errors at 100 correlation times (1.30 at 20 a batch) and 1.30 at 200 (1.08).
///
/// Why not Sokal's error itself: in a short series tau_int is estimated low exactly where the
/// mean has wandered (the autocovariances are taken about the wandered mean), so its error covers
/// only ~0.57 at 10 correlation times, and switching to it above a count picks the runs whose tau
/// was estimated low (Sokal times t covers 0.61-0.63 of those at 40 correlation times, 0.69 at 70,
/// while the halves cover 0.83-0.92 of the rest: 0.70-0.715 in all at 40-100). The count here
/// only sets how many batches and gaps; the batches' own scatter makes the error.
/// A single run shorter than ~7 correlation times cannot tell how far its mean has wandered: it
/// covers 0.59 at 3 and 0.45 at 1, and the count that would tell is itself the estimate that fails.
struct MeanError {
  enum class Basis { none, autocorrelation, two_halves, batch_means, two_stage };
  Basis basis = Basis::none;
  int batches = 0;              ///< k
  double stderr_of_mean = 0.0;  ///< NaN with basis none (fewer than 8 samples)
  double dof = 0.0;             ///< degrees of freedom of stderr_of_mean, k - 1
  double covering_error = 0.0;  ///< stderr_of_mean * t_dof, covering ~68 %
  static constexpr double kGapFraction = 0.1;
  static constexpr double kCorrelationTimesPerBatch = 40.0;
  static constexpr int kMaxBatches = 8;
};
/// `e` is autocorrelation_error(x); at most max_batches batches (the first stage of a precision
/// target asks fewer: stats/precision_target.hpp).
MeanError mean_error(const std::vector<double>& x, const AutocorrelationError& e,
                     int max_batches = MeanError::kMaxBatches);
/// summary.json's error_method: "gapped_batch_means", "two_halves", "two_stage" (a run the
/// precision target stopped), "sokal_autocorrelation" (runs of earlier builds) or "none".
const char* error_method_name(MeanError::Basis b);

/// time.target_rel_error's plan (stats/precision_target.hpp): at its first stage, n0 samples into
/// the window (which starts `cut` samples into what the run collected: time.average_from =
/// "auto"), the window's error (mean_error) had standard error se0 with dof0 degrees of freedom;
/// the run was planned to stop at `planned` samples. Unset: n0 = 0.
struct TwoStagePlan {
  std::int64_t n0 = 0;
  double se0 = 0.0, dof0 = 0.0, mean0 = 0.0;
  std::int64_t planned = 0;
  std::int64_t cut = 0;
  bool set() const { return n0 > 0; }
};
/// The error of the mean of the first n samples of a planned window (Stein's two-stage rule, C.
/// Stein, Ann. Math. Stat. 16, 243 (1945)): standard error se0 sqrt(n0 / n) at dof0 degrees of
/// freedom, basis two_stage. The length was fixed by se0 alone, so the mean of all n samples
/// scatters independently of se0, and t at dof0 covers whatever length se0 led to.
MeanError two_stage_error(const TwoStagePlan& plan, std::int64_t n);

/// The error of the mean of `series`, the per-step samples over [window_from_s, now_s]: Sokal's
/// estimate and its diagnostics (e), and the error the run reports (err; MeanError above): batch
/// means, as many batches as e's count of correlation times allows, the two halves at least;
/// the two-stage error of `plan` where time.target_rel_error stopped the run by it.
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
                         const TwoStagePlan* plan = nullptr);

/// The warning a finished window's error deserves, "" when none: no estimate of the correlation
/// time, fewer than AutocorrelationError::kWarnCorrelationTimes correlation times, or an
/// autocorrelation window that did not close; it says what the error rests on and what to do.
/// `what` names the quantity; `transient_end_s` (NaN: not known) shapes the advice: average from
/// where the detected transient ends when that is before the window, else run longer.
std::string window_warning(const WindowError& w, const std::string& what, double transient_end_s);

}  // namespace boycott::stats
