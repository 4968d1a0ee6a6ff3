#include "stats/autocorrelation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "stats/distributions.hpp"

namespace boycott::stats {

namespace {

// Autocovariances C(t) = 1/(N-t) sum_i y_i y_{i+t} of a centred series, computed as far as asked,
// four lags to a pass over y: each lag's sum keeps its own order of additions (the same bits as a
// pass per lag), in four independent chains of additions instead of one (a chain waits on each
// addition's latency) and with y read once for four lags.
class Autocovariances {
 public:
  explicit Autocovariances(const std::vector<double>& y) : y_(y) {}
  double operator()(std::size_t t) {
    constexpr std::size_t kLags = 4;
    const std::size_t n = y_.size();
    while (cov_.size() <= t) {
      const std::size_t t0 = cov_.size(), lags = std::min(kLags, n - t0);
      double acc[kLags] = {0.0, 0.0, 0.0, 0.0};
      const std::size_t common = n - (t0 + lags - 1);  // i below this: every lag of the pass has i + t < n
      for (std::size_t i = 0; i < common; ++i)
        for (std::size_t k = 0; k < kLags; ++k)
          if (k < lags) acc[k] += y_[i] * y_[i + t0 + k];
      for (std::size_t k = 0; k < lags; ++k) {
        for (std::size_t i = common; i + t0 + k < n; ++i) acc[k] += y_[i] * y_[i + t0 + k];
        cov_.push_back(acc[k] / static_cast<double>(n - t0 - k));
      }
    }
    return cov_[t];
  }

 private:
  const std::vector<double>& y_;
  std::vector<double> cov_;
};

// The correlation span 1/2 + sum_{t=1}^{M} |rho(t)| with the smallest window M >= c span(M), at
// most max_window, and that window.
std::pair<double, std::size_t> correlation_span(Autocovariances& autocov, std::size_t max_window) {
  const double c0 = autocov(0);
  double span = 0.5;
  for (std::size_t m = 1; m <= max_window; ++m) {
    span += std::abs(autocov(m)) / c0;
    if (static_cast<double>(m) >= AutocorrelationError::kWindowFactor * span) return {span, m};
  }
  return {span, max_window};
}

}  // namespace

AutocorrelationError autocorrelation_error(const std::vector<double>& x) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  using AE = AutocorrelationError;
  AE e;
  const std::size_t n = x.size();
  e.samples = static_cast<std::int64_t>(n);
  double sum = 0.0;
  for (double v : x) sum += v;
  e.mean = n ? sum / static_cast<double>(n) : kNaN;
  e.stderr_of_mean = e.tau_int = e.tau_int_upper = e.effective_samples = e.correlation_times = e.dof =
      e.covering_error = e.span = e.span_times = kNaN;
  if (n < 8) return e;
  const double N = static_cast<double>(n);
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = x[i] - e.mean;
  Autocovariances autocov(y);
  const double c0 = autocov(0);
  if (!(c0 > 0.0)) {  // a constant series: its mean is exact
    e.stderr_of_mean = e.covering_error = 0.0;
    e.dof = std::numeric_limits<double>::infinity();
    e.tau_int = e.tau_int_upper = e.span = 0.5;
    e.span_times = std::numeric_limits<double>::infinity();
    e.effective_samples = N;
    e.correlation_times = std::numeric_limits<double>::infinity();
    e.window_closed = true;
    return e;
  }
  // var(m) and tau_int for the window M, with the mean's bias solved for (see the header).
  double S = c0;  // sum over |t| <= M of C(t)
  auto var_of_mean = [&](std::size_t M) { return S / (N - 2.0 * static_cast<double>(M) - 1.0); };
  auto tau_of = [&](double V) { return N * V / (2.0 * (c0 + V)); };
  const std::size_t max_window = (n - 1) / 4;
  std::size_t M = 0;
  for (std::size_t m = 1; m <= max_window; ++m) {
    S += 2.0 * autocov(m);
    M = m;
    if (static_cast<double>(m) >= AE::kWindowFactor * tau_of(var_of_mean(m))) {
      e.window_closed = true;
      break;
    }
  }
  e.window = static_cast<std::int64_t>(M);
  const auto [span, span_window] = correlation_span(autocov, max_window);
  e.span = span;
  e.span_times = N / (span * (1.0 + std::sqrt(2.0 * (2.0 * static_cast<double>(span_window) + 1.0) / N)));
  const double V = var_of_mean(M);
  if (!(V > 0.0)) return e;  // anticorrelated noise summed below zero: no estimate
  e.tau_int = tau_of(V);
  e.tau_int_upper = e.tau_int * (1.0 + std::sqrt(2.0 * (2.0 * static_cast<double>(M) + 1.0) / N));
  e.effective_samples = N / (2.0 * e.tau_int);
  e.correlation_times = N / e.tau_int_upper;
  e.dof = N / (2.0 * static_cast<double>(M) + 1.0);
  if (e.correlation_times >= AE::kMinCorrelationTimes) {
    e.stderr_of_mean = std::sqrt(V);
    e.covering_error = e.stderr_of_mean * one_sigma_t_factor(e.dof);
  }
  return e;
}

}  // namespace boycott::stats
