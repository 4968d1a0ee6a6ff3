#pragma once
// The start-up transient of a series: where it ends, whether it biases a mean, and a window cut
// where it ends (time.average_from = "auto").
#include <cstdint>
#include <vector>

namespace boycott::stats {

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

}  // namespace boycott::stats
