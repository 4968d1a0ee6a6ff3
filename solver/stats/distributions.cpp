#include "stats/distributions.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>

namespace boycott::stats {
namespace {

// Out-of-range arguments give NaN (the callers' contract, documented in the header) rather than
// Boost's default exception; an overflowing result gives infinity.
using Policy =
    boost::math::policies::policy<boost::math::policies::domain_error<boost::math::policies::ignore_error>,
                                  boost::math::policies::overflow_error<boost::math::policies::ignore_error>>;
using StudentT = boost::math::students_t_distribution<double, Policy>;
using ChiSquared = boost::math::chi_squared_distribution<double, Policy>;
using FisherF = boost::math::fisher_f_distribution<double, Policy>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

double student_t_cdf(double t, double nu) {
  if (!(nu > 0.0) || std::isnan(t)) return kNaN;
  return boost::math::cdf(StudentT(nu), t);
}

double student_t_quantile(double p, double nu) {
  if (!(p > 0.0 && p < 1.0) || !(nu > 0.0)) return kNaN;
  return boost::math::quantile(StudentT(nu), p);
}

double one_sigma_t_factor(double nu) {
  return student_t_quantile(0.5 * (1.0 + kOneSigmaCoverage), nu);
}

double chi_square_cdf(double x, double k) {
  if (!(k > 0.0) || std::isnan(x)) return kNaN;
  if (!(x > 0.0)) return 0.0;
  if (std::isinf(x)) return 1.0;
  return boost::math::cdf(ChiSquared(k), x);
}

double f_cdf(double x, double d1, double d2) {
  if (!(d1 > 0.0) || !(d2 > 0.0) || std::isnan(x)) return kNaN;
  if (!(x > 0.0)) return 0.0;
  if (std::isinf(x)) return 1.0;
  // Boost's F takes finite degrees of freedom; d1 F(d1, inf) is chi-square with d1.
  if (std::isinf(d2)) return chi_square_cdf(d1 * x, d1);
  return boost::math::cdf(FisherF(d1, d2), x);
}

}  // namespace boycott::stats
