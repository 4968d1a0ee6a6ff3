#pragma once
// The error of the mean of a correlated series from its integrated autocorrelation time (Sokal).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace boycott::stats {

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
///
/// The correlation span, 1/2 + sum_{t=1}^{M'} |rho(t)| with its own window M' >= c span(M') (at
/// most N/4), is how long the series remembers itself whichever the sign: tau_int for a series
/// whose correlation is positive (AR(1), sums of them), but for a damped oscillation, whose lobes
/// cancel in tau_int (which can be far below the envelope's decay time, or no estimate at all), a
/// good part of the envelope's decay time (2/pi of it for a damped cosine). Batch means need
/// batches long against it (stats/window_error.hpp); span_times counts the spans in the series as
/// correlation_times counts tau_int, at the upper end of the one-sigma range of M' lags.
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
  double span = 0.0;               ///< correlation span, in samples (below)
  double span_times = 0.0;         ///< N / span_upper, the conservative count of spans
  /// Whether the error is to be doubted: fewer than kWarnCorrelationTimes, or no closed window.
  bool doubtful() const { return !window_closed || !(correlation_times >= kWarnCorrelationTimes); }
  /// The count that decides how long batches must be: the smaller of correlation_times and
  /// span_times, whichever has an estimate (NaN where neither has).
  double batch_count() const {
    if (std::isnan(span_times)) return correlation_times;
    if (std::isnan(correlation_times)) return span_times;
    return std::min(correlation_times, span_times);
  }
  static constexpr double kWarnCorrelationTimes = 20.0;
  static constexpr double kMinCorrelationTimes = 5.0;
  static constexpr double kWindowFactor = 6.0;  ///< c
};
/// Needs 8 samples at least (fewer: everything NaN but samples and mean). A constant series has
/// error 0.
AutocorrelationError autocorrelation_error(const std::vector<double>& x);

}  // namespace boycott::stats
