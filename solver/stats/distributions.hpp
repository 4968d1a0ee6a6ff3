#pragma once
// The sampling distributions an error bar needs: Student's t (the mean of a few numbers over
// their own scatter), chi-square (a scatter against known errors) and F (a scatter against
// errors that are themselves estimated), from Boost.Math (Debian's libboost-math-dev, header
// only): its documented accuracy, tails and non-integer degrees of freedom, tested far beyond what
// a project of our own could. Arguments outside a function's domain give NaN.

namespace boycott::stats {

/// The probability inside +-1 standard deviation of a normal distribution, 0.6827: the coverage
/// an error bar of one standard error promises.
inline constexpr double kOneSigmaCoverage = 0.682689492137086;

/// P(T <= t) for Student's t with nu > 0 degrees of freedom (nu need not be whole).
double student_t_cdf(double t, double nu);
/// The p-quantile of Student's t with nu > 0 degrees of freedom (p in (0, 1)); infinite nu:
/// the normal quantile.
double student_t_quantile(double p, double nu);
/// The factor turning a standard error with nu degrees of freedom into a half-width that covers
/// kOneSigmaCoverage: the t quantile at (1 + 0.6827)/2 (1.84 at nu = 1, 1.32 at 2, 1.05 at 10,
/// 1 as nu grows).
double one_sigma_t_factor(double nu);

/// P(X <= x) for chi-square with k > 0 degrees of freedom.
double chi_square_cdf(double x, double k);

/// P(F <= x) for Fisher's F with d1 > 0 and d2 > 0 degrees of freedom (infinite d2: chi-square
/// with d1 over d1).
double f_cdf(double x, double d1, double d2);

}  // namespace boycott::stats
