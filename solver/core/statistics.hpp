#pragma once
// Time averages of correlated series. The standard error of the mean of an autocorrelated
// series is underestimated by sigma/sqrt(N); batch means (Flyvbjerg & Petersen 1989, Law &
// Kelton) group the series into B consecutive batches long enough to be nearly independent and
// use the scatter of the batch means: SE = sd(batch means)/sqrt(B). Batch means never checks
// that a batch is longer than the correlation time; autocorrelation_error() estimates the
// correlation time itself from the whole series.
#include <cstdint>
#include <vector>

namespace boycott {

/// Incremental batch-means estimator with O(B) state: samples fill batches of size `batch_len`;
/// when 2B batches are full, neighbouring batches are merged and batch_len doubles, so any
/// series length ends with between B and 2B batches. Its whole state is plain numbers (for
/// checkpoints).
class BatchMeans {
 public:
  explicit BatchMeans(int min_batches = 16) : min_batches_(min_batches) {}
  void add(double x);
  std::int64_t count() const { return count_; }
  double mean() const;
  /// Standard error of the mean from the complete batches (NaN with fewer than 4 batches).
  double stderr_of_mean() const;
  int batches() const { return static_cast<int>(sums_.size()); }

  // State, for checkpoints.
  int min_batches_;
  std::int64_t count_ = 0;
  std::int64_t batch_len_ = 1;
  double total_ = 0.0;
  std::vector<double> sums_;  ///< sums of the complete batches
  double open_sum_ = 0.0;     ///< the batch being filled
  std::int64_t open_n_ = 0;
};

/// The standard error of the mean of a stationary, autocorrelated series from its integrated
/// autocorrelation time, with Sokal's automatic window (A. D. Sokal, "Monte Carlo methods in
/// statistical mechanics: foundations and new algorithms", 1997, sec. 3; N. Madras & A. D. Sokal,
/// J. Stat. Phys. 50, 109 (1988)). No model of the autocorrelation is assumed:
///   C(t) = 1/(N-t) sum_i (x_i - m)(x_{i+t} - m),   tau_int(M) = 1/2 + sum_{t=1}^{M} rho(t),
///   var(m) = 2 tau_int C(0) / N,
/// with the window M the smallest one with M >= c tau_int(M) (c = 6), at most N/4. The sample
/// mean m biases every C(t) low by var(m); summed over the 2M+1 lags of the window that is a
/// relative bias of (2M+1)/N, which matters in short series, so var(m) is solved for
/// self-consistently, var(m) = S / (N - 2M - 1) with S = sum_{|t|<=M} C(t), and C(0) + var(m)
/// stands for the variance (first order in tau/N; Wolff, Comput. Phys. Commun. 156, 143 (2004),
/// corrects the same bias to the same order).
///
/// How many correlation times the series holds, N / tau_int, decides how far the error can be
/// trusted. tau_int's own standard error is tau sqrt(2(2M+1)/N) (Madras & Sokal), large in short
/// series, whose estimates also scatter low: the count is taken at the upper end of that
/// one-sigma range, K = N / (tau (1 + sqrt(2(2M+1)/N))). Below kWarnCorrelationTimes (or when
/// the window could not close) the error comes with a warning; below kMinCorrelationTimes it is
/// not reported (NaN).
///
/// The standard error is itself estimated, from a series that holds only so many independent
/// pieces of information: its square scatters like a chi-square with dof = N / (2M + 1) degrees of
/// freedom (the relative variance 2(2M+1)/N of tau_int above, Madras & Sokal), so the half-width
/// that covers 68 % is the standard error times Student's t at that dof (covering_error). On AR(1)
/// series it covers 0.69-0.70 at 20 correlation times, 0.71-0.73 at 50-100 and 0.70 at 300, where
/// the plain standard error covers 0.59-0.61 at 20 (docs/validation.md, "Error bars").
struct AutocorrelationError {
  std::int64_t samples = 0;
  double mean = 0.0;
  double stderr_of_mean = 0.0;     ///< NaN: not available (too few correlation times, or none)
  double tau_int = 0.0;            ///< integrated autocorrelation time, in samples
  double tau_int_upper = 0.0;      ///< its one-sigma upper end, in samples
  std::int64_t window = 0;         ///< M
  bool window_closed = false;      ///< M >= c tau_int(M) was reached within N/4
  double effective_samples = 0.0;  ///< N / (2 tau_int)
  double correlation_times = 0.0;  ///< N / tau_int_upper (the conservative count above)
  double dof = 0.0;                ///< N / (2M + 1), the degrees of freedom of stderr_of_mean
  double covering_error = 0.0;     ///< stderr_of_mean * t_dof, covering ~68 %; NaN with it
  /// Whether the error is to be doubted: fewer than kWarnCorrelationTimes, or no closed window.
  bool doubtful() const { return !window_closed || !(correlation_times >= kWarnCorrelationTimes); }
  static constexpr double kWarnCorrelationTimes = 20.0;
  static constexpr double kMinCorrelationTimes = 5.0;
  static constexpr double kWindowFactor = 6.0;  ///< c
};
/// Needs 8 samples at least (fewer: everything NaN but samples and mean). A constant series has
/// error 0.
AutocorrelationError autocorrelation_error(const std::vector<double>& x);

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
/// (scenes/mean_error.hpp, PrecisionTarget).
MeanError sokal_mean_error(const AutocorrelationError& e);
/// summary.json's error_method: "gapped_batch_means", "two_halves", "sokal_autocorrelation" or "none".
const char* error_method_name(MeanError::Basis b);

/// Where a series' start-up transient ends: the later of two cuts, each searched in the first
/// half, since each sees a kind of transient the other misses.
/// - The truncation that leaves the most effective samples, max over t0 of
///   (N - t0) / (2 tau_int(x[t0..])) (J. D. Chodera, J. Chem. Theory Comput. 12, 1799 (2016)): a
///   slow drift inflates the correlation time of what follows it. A long series is first averaged
///   in blocks to at most kMaxBlocks values (the correlation time survives blocking) and kCandidates
///   starts are tried, so the cost stays ~ N.
/// - MSER-5 (K. P. White, Simulation 69, 323 (1997)): the truncation that minimises the marginal
///   standard error, sum over i >= t0 of (b_i - mean)^2 / (n - t0)^2 over batch means b of kBatch
///   samples (more where needed for at most kMaxBlocks). A start-up that overshoots and swings back
///   within a few correlation times (stages I and II of a settling run) looks less correlated than
///   what follows, so the first keeps it; it inflates the spread, which MSER sees. On a slow decay
///   MSER alone cuts too early (test TransientEnd.*: 87 % of series left unbiased against 90 %).
struct TransientEnd {
  std::int64_t start = 0;          ///< first sample of the stationary part
  double effective_samples = 0.0;  ///< (N - start) / (2 tau_int), counted on the blocks; NaN: no estimate
  static constexpr int kCandidates = 40;
  static constexpr std::int64_t kBatch = 5;
  static constexpr std::int64_t kMaxBlocks = 2000;
};
TransientEnd transient_end(const std::vector<double>& x);

/// Whether the samples between `from` and `start` (the detected end of the transient, from <
/// start) are a transient that matters rather than noise: their mean differs from the stationary
/// part's by more than kTransientSignificance standard errors of the difference, the head's
/// error taken as if it were more of the stationary part (its own would be inflated by a trend).
/// 2.25 rather than 2 because the cut was chosen where the head looks most unlike the rest: on
/// stationary AR(1) series it fires for 7 % (2: 11 %), on a transient that biases the mean by one
/// standard error for 93 % (tests TransientEnd.*).
bool transient_biases_mean(const std::vector<double>& x, std::int64_t from, std::int64_t start);
inline constexpr double kTransientSignificance = 2.25;

/// Fixed-range histogram normalised as a probability density (values outside are counted apart).
class Histogram {
 public:
  Histogram(double lo, double hi, int bins) : lo_(lo), hi_(hi), counts_(bins, 0.0) {}
  void add(double x, double weight = 1.0);
  std::vector<double> density() const;
  double bin_center(int b) const { return lo_ + (b + 0.5) * (hi_ - lo_) / counts_.size(); }
  int bins() const { return static_cast<int>(counts_.size()); }
  double lo_, hi_;
  std::vector<double> counts_;
  double outside_ = 0.0;
  double total_ = 0.0;
};

}  // namespace boycott
