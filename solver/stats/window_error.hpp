#pragma once
// The error of a time average over its averaging window: the rule a run reports it by (MeanError:
// gapped batch means, the two halves at least, or Sokal's where a precision target stopped the
// run) and the window's error with its diagnostics (WindowError), as summary.json states them
// (scenes/summary_statistics.hpp).
#include <vector>

#include "stats/autocorrelation.hpp"

namespace boycott::stats {

/// The error one run reports for the mean of its series, and what it rests on: batch means with
/// Student's t at k - 1 degrees of freedom (Schmeiser, Oper. Res. 30, 556 (1982); Law & Kelton).
/// The series is cut into k batches of equal length with gaps between them, and the standard error
/// is sd(batch means) / sqrt(k). Batch means are nearly independent when each batch is much longer
/// than the correlation time: neighbours correlate through the samples either side of their
/// border (by ~tau_int / (2 b) for an exponential decay), so one correlation time (the upper end
/// of its estimate) is left out at each border, at most a tenth of the series (kGapFraction; a
/// tenth too where no count could be made). k is as many batches of kCorrelationTimesPerBatch
/// correlation times as the conservative count (AutocorrelationError::correlation_times) allows,
/// two at least: the two halves of the series (basis two_halves, 1 degree of freedom, t = 1.84)
/// in runs of fewer than 60 counted correlation times, where no count could be made, and always
/// in short series.
///
/// Why not Sokal's error itself: in a short series tau_int is estimated low exactly where the
/// mean has wandered (the autocovariances are taken about the wandered mean), so its error covers
/// only ~0.57 at 10 correlation times, and switching to it above a count picks the runs whose tau
/// was estimated low (Sokal times t covers 0.61-0.63 of those at 40 correlation times, 0.69 at 70,
/// while the halves cover 0.83-0.92 of the rest: 0.70-0.715 in all at 40-100). The count here
/// only sets how many batches and gaps; the batches' own scatter makes the error. On AR(1) series
/// (tau_int 3, 10 and 30 steps) the rule covers 0.66-0.69 from 10 to 500 correlation times; its
/// half-width is 1.3-1.5 times the true standard error at 10-100 (few degrees of freedom), 1.08 at
/// 200, 1.02 at 500 (docs/validation.md, "One run"). Batches of 10 correlation times cover 0.65
/// at 50; a tenth of the series as gaps at every k, 0.70-0.705 at 200-500 (the error of the mean
/// of less than the whole series).
/// A single run shorter than ~7 correlation times cannot tell how far its mean has wandered: it
/// covers 0.59 at 3 and 0.45 at 1, and the count that would tell is itself the estimate that fails.
struct MeanError {
  enum class Basis { none, autocorrelation, two_halves, batch_means };
  Basis basis = Basis::none;
  int batches = 0;              ///< k
  double stderr_of_mean = 0.0;  ///< NaN with basis none (fewer than 8 samples)
  double dof = 0.0;             ///< degrees of freedom of stderr_of_mean, k - 1
  double covering_error = 0.0;  ///< stderr_of_mean * t_dof, covering ~68 %
  static constexpr double kGapFraction = 0.1;
  static constexpr double kCorrelationTimesPerBatch = 20.0;
};
/// `e` is autocorrelation_error(x).
MeanError mean_error(const std::vector<double>& x, const AutocorrelationError& e);
/// Sokal's estimate as a MeanError (basis autocorrelation, N / (2M + 1) degrees of freedom): the
/// error of a run that time.target_rel_error stopped, the one its stop was judged on
/// (stats/precision_target.hpp, PrecisionTarget).
MeanError sokal_mean_error(const AutocorrelationError& e);
/// summary.json's error_method: "gapped_batch_means", "two_halves", "sokal_autocorrelation" or "none".
const char* error_method_name(MeanError::Basis b);

/// The error of the mean of `series`, the per-step samples over [window_from_s, now_s]: Sokal's
/// estimate and its diagnostics (e), and the error the run reports (err; MeanError above): batch
/// means, as many batches as e's count of correlation times allows, the two halves at least;
/// Sokal's own where time.target_rel_error stopped the run (`stopped_by_target`), since the stop
/// was judged on it and its coverage measured under that stop (PrecisionTarget).
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

}  // namespace boycott::stats
