#include "stats/distributions.hpp"

#include <cmath>
#include <limits>

namespace boycott::stats {
namespace {

constexpr double kTiny = 1e-300;
constexpr double kEps = 1e-15;
constexpr int kMaxTerms = 500;

double lentz_clamp(double v) {
  return std::abs(v) < kTiny ? kTiny : v;
}

// Continued fraction of the incomplete beta function I_x(a, b) (A&S 26.5.8).
double beta_fraction(double a, double b, double x) {
  double c = 1.0, d = 1.0 / lentz_clamp(1.0 - (a + b) * x / (a + 1.0));
  double h = d;
  for (int m = 1; m <= kMaxTerms; ++m) {
    const double m2 = 2.0 * m;
    const double even = m * (b - m) * x / ((a - 1.0 + m2) * (a + m2));
    d = 1.0 / lentz_clamp(1.0 + even * d);
    c = lentz_clamp(1.0 + even / c);
    h *= d * c;
    const double odd = -(a + m) * (a + b + m) * x / ((a + m2) * (a + 1.0 + m2));
    d = 1.0 / lentz_clamp(1.0 + odd * d);
    c = lentz_clamp(1.0 + odd / c);
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < kEps) break;
  }
  return h;
}

// Regularised incomplete beta I_x(a, b); the fraction converges fast below x = (a+1)/(a+b+2),
// above it through the symmetry I_x(a, b) = 1 - I_{1-x}(b, a).
double incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(a, b, x) / a;
  return 1.0 - front * beta_fraction(b, a, 1.0 - x) / b;
}

// Regularised lower incomplete gamma P(a, x): its series below x = a + 1 (A&S 6.5.29), the
// continued fraction of Q = 1 - P above (A&S 6.5.31).
double incomplete_gamma(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double front = std::exp(-x + a * std::log(x) - std::lgamma(a));
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n <= kMaxTerms && std::abs(term) > kEps * std::abs(sum); ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return front * sum;
  }
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int n = 1; n <= kMaxTerms; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = 1.0 / lentz_clamp(an * d + b);
    c = lentz_clamp(b + an / c);
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < kEps) break;
  }
  return 1.0 - front * h;
}

}  // namespace

double student_t_cdf(double t, double nu) {
  if (!(nu > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double tail = 0.5 * incomplete_beta(0.5 * nu, 0.5, nu / (nu + t * t));
  return t > 0.0 ? 1.0 - tail : tail;
}

double student_t_quantile(double p, double nu) {
  if (!(p > 0.0 && p < 1.0) || !(nu > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (p < 0.5) return -student_t_quantile(1.0 - p, nu);
  const auto cdf = [nu](double t) {
    return std::isinf(nu) ? 0.5 * std::erfc(-t / std::sqrt(2.0)) : student_t_cdf(t, nu);
  };
  // Bisection on the monotone cdf to double precision.
  double lo = 0.0, hi = 1.0;
  while (cdf(hi) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double one_sigma_t_factor(double nu) {
  return student_t_quantile(0.5 * (1.0 + kOneSigmaCoverage), nu);
}

double chi_square_cdf(double x, double k) {
  if (!(k > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return incomplete_gamma(0.5 * k, 0.5 * x);
}

double f_cdf(double x, double d1, double d2) {
  if (!(d1 > 0.0) || !(d2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (!(x > 0.0)) return 0.0;
  if (std::isinf(d2)) return chi_square_cdf(d1 * x, d1);
  return incomplete_beta(0.5 * d1, 0.5 * d2, d1 * x / (d1 * x + d2));
}

}  // namespace boycott::stats
