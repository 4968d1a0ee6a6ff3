// The sampling distributions every error bar passes through (stats/distributions.hpp, from
// Boost.Math), checked where printed tables do not reach: the tails (p = 0.001 and 0.999),
// degrees of freedom that are not whole (Welch-Satterthwaite gives such), and from 1 to 10^6
// degrees of freedom. References independent of Boost: closed forms (Student's t at 1 and 2
// degrees of freedom, chi-square at 2), the Cornish-Fisher expansion of t's quantile in 1/nu
// (Abramowitz & Stegun 26.7.5, five terms), and the densities integrated numerically after a
// change of variable that makes them smooth. The printed tables are in test_error_coverage.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "stats/distributions.hpp"

using namespace boycott::stats;

namespace {

// Composite Simpson rule on [a, b] with n (even) intervals.
double simpson(const std::function<double(double)>& f, double a, double b, int n = 200000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
  return s * h / 3.0;
}

// P(T <= t) for Student's t: 1/2 plus the density's integral from 0 to t (smooth there).
double t_cdf_by_quadrature(double t, double nu) {
  const double c =
      std::exp(std::lgamma(0.5 * (nu + 1.0)) - std::lgamma(0.5 * nu)) / std::sqrt(nu * std::numbers::pi);
  const double half =
      simpson([&](double s) { return c * std::pow(1.0 + s * s / nu, -0.5 * (nu + 1.0)); }, 0.0, std::abs(t));
  return t >= 0.0 ? 0.5 + half : 0.5 - half;
}

// The regularised incomplete beta I_z(a, b) for z < 1 by quadrature of the beta density with
// t = u^m, m = ceil(a) / a, which turns t^(a-1) dt into m u^(ceil(a) - 1) du: a polynomial in u, so
// no fractional power spoils the rule at 0.
double beta_cdf_by_quadrature(double z, double a, double b) {
  const double lbeta = std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b), n = std::ceil(a), m = n / a;
  const auto f = [&](double u) {
    const double t = std::pow(u, m);
    return m * std::pow(u, n - 1.0) * std::exp((b - 1.0) * std::log1p(-t) - lbeta);
  };
  return simpson(f, 0.0, std::pow(z, 1.0 / m));
}

// The chi-square cdf with k degrees of freedom by quadrature, with the same change of variable.
double chi_square_cdf_by_quadrature(double x, double k) {
  const double a = 0.5 * k, lg = std::lgamma(a) + a * std::log(2.0), n = std::ceil(a), m = n / a;
  const auto f = [&](double u) { return m * std::pow(u, n - 1.0) * std::exp(-0.5 * std::pow(u, m) - lg); };
  return simpson(f, 0.0, std::pow(x, 1.0 / m));
}

// The standard normal's quantile by Newton's method on erfc (to round-off).
double normal_quantile(double p) {
  double z = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    const double step = (cdf - p) / (std::exp(-0.5 * z * z) / std::sqrt(2.0 * std::numbers::pi));
    z -= step;
    if (std::abs(step) < 1e-16 * (1.0 + std::abs(z))) break;
  }
  return z;
}

// Student's t quantile for large nu: Cornish-Fisher in 1/nu to the fourth power (A&S 26.7.5);
// the first term left out is of order z^11 / nu^5.
double t_quantile_cornish_fisher(double p, double nu) {
  const double z = normal_quantile(p), z2 = z * z;
  const double g1 = (z2 + 1.0) * z / 4.0;
  const double g2 = ((5.0 * z2 + 16.0) * z2 + 3.0) * z / 96.0;
  const double g3 = (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) * z / 384.0;
  const double g4 = ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) * z / 92160.0;
  return z + g1 / nu + g2 / (nu * nu) + g3 / (nu * nu * nu) + g4 / (nu * nu * nu * nu);
}

}  // namespace

TEST(Distributions, StudentTQuantilesInTheTailsMatchTheClosedFormsAtOneAndTwoDegreesOfFreedom) {
  for (double p : {0.001, 0.01, 0.1587, 0.5, 0.8413, 0.975, 0.999}) {
    // One degree of freedom: Cauchy, tan(pi (p - 1/2)); two: (2p - 1) / sqrt(2 p (1 - p)).
    const double cauchy = std::tan(std::numbers::pi * (p - 0.5));
    const double two = (2.0 * p - 1.0) / std::sqrt(2.0 * p * (1.0 - p));
    EXPECT_NEAR(student_t_quantile(p, 1.0), cauchy, 1e-12 * (1.0 + std::abs(cauchy))) << p;
    EXPECT_NEAR(student_t_quantile(p, 2.0), two, 1e-12 * (1.0 + std::abs(two))) << p;
  }
}

TEST(Distributions, StudentTAtNonIntegerDegreesOfFreedomMatchesItsIntegratedDensity) {
  for (double nu : {1.3, 2.7}) {
    for (double p : {0.001, 0.999}) {
      const double t = student_t_quantile(p, nu);
      // The quantile lands where the integrated density reaches p; the cdf there agrees with it.
      EXPECT_NEAR(t_cdf_by_quadrature(t, nu), p, 1e-10) << "nu " << nu << ", p " << p;
      EXPECT_NEAR(student_t_cdf(t, nu), p, 1e-13) << "nu " << nu << ", p " << p;
    }
    for (double t : {-3.0, 0.7, 1.0, 12.0})
      EXPECT_NEAR(student_t_cdf(t, nu), t_cdf_by_quadrature(t, nu), 1e-10) << nu;
  }
}

TEST(Distributions, StudentTFromOneToAMillionDegreesOfFreedomMatchesCornishFisherAndInvertsItsCdf) {
  // The one-sigma factor and the 0.999 point against the expansion where it is exact to
  // round-off (nu >= 1000), and cdf(quantile(p)) = p at every decade from 1 to 10^6.
  for (double nu : {1e3, 1e4, 1e5, 1e6}) {
    EXPECT_NEAR(one_sigma_t_factor(nu), t_quantile_cornish_fisher(0.5 * (1.0 + kOneSigmaCoverage), nu), 1e-12)
        << nu;
    EXPECT_NEAR(student_t_quantile(0.999, nu), t_quantile_cornish_fisher(0.999, nu), 1e-11) << nu;
  }
  for (double nu = 1.0; nu <= 1e6; nu *= 10.0)
    for (double p : {0.001, 0.8413, 0.999})
      EXPECT_NEAR(student_t_cdf(student_t_quantile(p, nu), nu), p, 1e-13) << nu;
  // Degrees of freedom without end: the normal distribution.
  EXPECT_NEAR(student_t_quantile(0.999, INFINITY), normal_quantile(0.999), 1e-13);
  EXPECT_NEAR(student_t_cdf(1.0, INFINITY), 0.5 * std::erfc(-1.0 / std::sqrt(2.0)), 1e-15);
}

TEST(Distributions, ChiSquareAndFAtNonIntegerDegreesOfFreedomMatchTheirIntegratedDensities) {
  // Chi-square with 2 degrees of freedom is exponential: 1 - exp(-x / 2).
  for (double x : {0.002, 1.0, 13.8155})
    EXPECT_NEAR(chi_square_cdf(x, 2.0), -std::expm1(-0.5 * x), 1e-14) << x;
  for (double k : {1.3, 2.7})
    for (double x : {0.001, 0.5, 3.0, 15.0})
      EXPECT_NEAR(chi_square_cdf(x, k), chi_square_cdf_by_quadrature(x, k), 1e-10) << k;
  // F(d1, d2) <= x is a beta variable: I_z(d1/2, d2/2) at z = d1 x / (d1 x + d2).
  for (const auto& [d1, d2] : {std::pair{1.3, 2.7}, std::pair{2.7, 1.3}, std::pair{4.0, 30.5}})
    for (double x : {0.01, 1.0, 6.0}) {
      const double z = d1 * x / (d1 * x + d2);
      EXPECT_NEAR(f_cdf(x, d1, d2), beta_cdf_by_quadrature(z, 0.5 * d1, 0.5 * d2), 1e-10)
          << d1 << " " << d2 << " " << x;
    }
}

TEST(Distributions, ArgumentsOutsideTheDomainGiveNotANumberAndTheEndsGiveZeroAndOne) {
  EXPECT_TRUE(std::isnan(student_t_quantile(0.0, 3.0)));
  EXPECT_TRUE(std::isnan(student_t_quantile(1.0, 3.0)));
  EXPECT_TRUE(std::isnan(student_t_quantile(0.5, 0.0)));
  EXPECT_TRUE(std::isnan(student_t_cdf(1.0, -1.0)));
  EXPECT_TRUE(std::isnan(chi_square_cdf(1.0, 0.0)));
  EXPECT_TRUE(std::isnan(f_cdf(1.0, 0.0, 3.0)));
  EXPECT_EQ(student_t_cdf(INFINITY, 3.0), 1.0);
  EXPECT_EQ(student_t_cdf(-INFINITY, 3.0), 0.0);
  EXPECT_EQ(chi_square_cdf(-1.0, 3.0), 0.0);
  EXPECT_EQ(f_cdf(0.0, 2.0, 3.0), 0.0);
  EXPECT_EQ(f_cdf(INFINITY, 2.0, 3.0), 1.0);
}
