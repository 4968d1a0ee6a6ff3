#pragma once
// Families of stationary series with known mean (0) and known standard error of the mean, on
// which the coverage tests measure the product's error rules: AR(1), sums of two AR(1) processes
// whose correlation times are 3-30 times apart, and a damped oscillation (AR(2) with complex
// roots) plus white noise. Each draws its parameters at random per series from a stated range, so
// a figure is not tuned to one process. Units: steps (samples); every series has unit variance.
#include <cmath>
#include <random>
#include <vector>

namespace boycott::testing {

/// AR(1) with unit stationary variance and integrated autocorrelation time tau_int (steps):
/// phi = (2 tau_int - 1) / (2 tau_int + 1), since tau_int = (1 + phi) / (2 (1 - phi)).
inline double ar1_phi(double tau_int) {
  return (2.0 * tau_int - 1.0) / (2.0 * tau_int + 1.0);
}

/// Adds `scale` times a stationary AR(1) of integrated time tau_int to x.
inline void add_ar1(std::vector<double>& x, double tau_int, double scale, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  const double phi = ar1_phi(tau_int), sd = std::sqrt(1.0 - phi * phi);
  double v = g(rng);
  for (auto& xi : x) xi += scale * (v = phi * v + sd * g(rng));
}

/// A series and what it is measured against: the true standard error of the mean of its n
/// samples (sqrt(2 tau_int / n) to first order) and its slowest time scale (steps): the slow
/// AR(1)'s tau_int, or an oscillation's envelope decay time.
struct FamilySeries {
  std::vector<double> x;
  double tau_int = 0.0;
  double slowest = 0.0;
  double true_se() const { return std::sqrt(2.0 * tau_int / static_cast<double>(x.size())); }
};

/// AR(1) of tau_int `tau` over `window` correlation times.
inline FamilySeries ar1_series(double tau, double window, std::mt19937_64& rng) {
  FamilySeries s{std::vector<double>(static_cast<std::size_t>(window * tau), 0.0), tau, tau};
  add_ar1(s.x, tau, 1.0, rng);
  return s;
}

/// Two AR(1) processes: a fast one of tau_int 2-5 steps and a slow one 3-30 times slower (ratio
/// log-uniform) carrying 0.1-0.5 of the variance (uniform), over `window` slow correlation times.
/// tau_int of the sum: (1 - s) tau_fast + s tau_slow.
inline FamilySeries two_scale_series(double window, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double tau_fast = 2.0 + 3.0 * u(rng);
  const double ratio = 3.0 * std::pow(10.0, u(rng));
  const double share = 0.1 + 0.4 * u(rng);
  const double tau_slow = ratio * tau_fast;
  FamilySeries s{std::vector<double>(static_cast<std::size_t>(window * tau_slow), 0.0),
                 (1.0 - share) * tau_fast + share * tau_slow, tau_slow};
  add_ar1(s.x, tau_fast, std::sqrt(1.0 - share), rng);
  add_ar1(s.x, tau_slow, std::sqrt(share), rng);
  return s;
}

/// A damped oscillation plus white noise: AR(2) x_t = 2 r cos(w) x_{t-1} - r^2 x_{t-2} + e_t with
/// period 2 pi / w of 8-40 steps (uniform, not dividing the window), envelope decay time
/// -1 / ln r of 1-4 periods, carrying 0.4-0.8 of the variance, the rest white noise; over `window`
/// envelope decay times. Its autocorrelation sums to sigma_e^2 / (1 - a1 - a2)^2 over the AR(2)'s
/// variance, so tau_int = (1 - q) tau_ar2 + q / 2 for noise share q.
inline FamilySeries oscillation_series(double window, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  const double pi = std::acos(-1.0);
  const double period = 8.0 + 32.0 * u(rng);
  const double decay = period * (1.0 + 3.0 * u(rng));
  const double osc_share = 0.4 + 0.4 * u(rng);
  const double r = std::exp(-1.0 / decay), a1 = 2.0 * r * std::cos(2.0 * pi / period), a2 = -r * r;
  // Stationary variance of the AR(2) for unit innovations.
  const double var = (1.0 - a2) / ((1.0 + a2) * ((1.0 - a2) * (1.0 - a2) - a1 * a1));
  const double tau_ar2 = 1.0 / ((1.0 - a1 - a2) * (1.0 - a1 - a2) * var) / 2.0;
  const auto n = static_cast<std::size_t>(window * decay);
  FamilySeries s{std::vector<double>(n, 0.0), osc_share * tau_ar2 + (1.0 - osc_share) / 2.0, decay};
  const double scale = std::sqrt(osc_share / var), noise = std::sqrt(1.0 - osc_share);
  // Started from the stationary state by a burn-in of 20 decay times.
  double x1 = 0.0, x2 = 0.0;
  for (int i = 0; i < static_cast<int>(20.0 * decay); ++i) {
    const double v = a1 * x1 + a2 * x2 + g(rng);
    x2 = x1, x1 = v;
  }
  for (auto& xi : s.x) {
    const double v = a1 * x1 + a2 * x2 + g(rng);
    x2 = x1, x1 = v;
    xi = scale * v + noise * g(rng);
  }
  return s;
}

}  // namespace boycott::testing
