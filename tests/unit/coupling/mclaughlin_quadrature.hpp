#pragma once
// McLaughlin's (1991) J(epsilon) by quadrature of the outer problem he and Saffman (1965) solve:
// the reference the tabulated J of coupling/lift_laws.hpp is checked against (and was made by;
// the table test of test_mclaughlin_table.cpp prints it anew).
//
// The problem. A sphere of radius a at the origin, in the frame moving with it, sits in the
// linear shear U = (U_s + G y) e_x (U_s: the slip, fluid minus particle, along x; G > 0). Far from
// it (the outer region, lengths of L = (nu / G)^1/2) it is the point force -F e_x, F = 6 pi mu a
// U_s, on the fluid, whose disturbance u obeys the Navier-Stokes equations linearised about U,
//   (U . grad) u + (u . grad) U = -grad p / rho + nu lap u - (F / rho) e_x delta(x),  div u = 0.
// The lift is the Stokes drag of the uniform velocity that the outer flow adds at the particle
// (u less its Stokeslet): F_L = 6 pi mu a v(0). With Saffman's normalisation
//   F_L = (9 / pi) mu a^2 U_s (G / nu)^1/2 J(epsilon),   epsilon = (G nu)^1/2 / U_s
// (McLaughlin's epsilon = Re_G^1/2 / Re_s, the same with radii or diameters), J(inf) is Saffman's
// 6.46 pi / 9.
//
// Fourier transform (K = k L, hats, w = v-hat rho G / F): the pressure drops out of the y
// component (Saffman's step), leaving along each line of K_y at fixed (K_x, K_z)
//   K_x dw/dK_y = (K^2 + i K_x / epsilon - 2 K_x K_y / K^2) w - K_x K_y / K^2,
// whose solution bounded at both ends is, for K_x > 0 (and its complex conjugate at -K),
//   w = (1 / K^2) int_0^inf (K_y + t) exp(-[K^2 t + K_y t^2 + t^3 / 3] / K_x - i t / epsilon) dt,
// and J = (1/2) int w d^3K (the Stokeslet K_x K_y / K^4 integrates to zero). With t = K_x tau
// and K = k (alpha, beta, gamma) on the unit sphere the k integral is Gaussian; its real part
// is all that survives the conjugate pair:
//   J = (sqrt(pi) / 4) int dOmega int_0^inf dtau alpha (beta + alpha tau) (tau P)^-3/2
//         (2 - z^2) exp(-z^2 / 4),
//   P = 1 + alpha beta tau + alpha^2 tau^2 / 3,   z^2 = alpha^2 tau / (epsilon^2 P),
// over the quarter sphere alpha > 0, gamma > 0. The beta and -beta halves are summed before the
// tau integral: each alone grows as tau^-3/2 at small tau (the Stokeslet), their sum as tau^-1/2.
// The sum is formed without cancellation (its differences written as products), which is what
// keeps the small-epsilon values, J ~ 1e-5, accurate.
//
// Checks of this formulation (test_mclaughlin_lift.cpp): J(inf) = 2.25358 (Saffman's 6.46 pi / 9
// = 2.2549 to the three figures he gave, McLaughlin's 2.255); J -> -32 pi^2 epsilon^5
// ln(epsilon^-2) at small epsilon (McLaughlin's eq. 3.27, its leading coefficient to 1 %);
// J(inf) - J -> 0.6628 / epsilon^2 at large epsilon (McLaughlin's eq. 3.26 prints 0.6463).
#include <cmath>
#include <functional>

namespace boycott::test {

/// Adaptive Gauss-Kronrod (7-15) integral of f over [a, b] to an absolute error of about abstol.
inline double gauss_kronrod(const std::function<double(double)>& f, double a, double b, double abstol,
                            int depth = 0) {
  static constexpr double x[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                                  0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                                  0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                                  0.207784955007898467600689403773245, 0.0};
  static constexpr double wk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                   0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                   0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                   0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  static constexpr double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                   0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  const double fc = f(c);
  double k = fc * wk[7], g = fc * wg[3];
  for (int j = 0; j < 7; ++j) {
    const double f1 = f(c - h * x[j]), f2 = f(c + h * x[j]);
    k += wk[j] * (f1 + f2);
    if (j % 2 == 1) g += wg[j / 2] * (f1 + f2);
  }
  if (std::abs((k - g) * h) <= abstol || depth > 40) return k * h;
  return gauss_kronrod(f, a, c, 0.5 * abstol, depth + 1) + gauss_kronrod(f, c, b, 0.5 * abstol, depth + 1);
}

/// The tau integrand with its beta and -beta halves summed: alpha [beta (g(P+) - g(P-)) +
/// alpha tau (g(P+) + g(P-))] / tau^3/2, g(P) = P^-3/2 E(c / P), E(x) = (2 - x) e^-x/4,
/// P+- = M +- delta, c = alpha^2 tau / epsilon^2 (inv_eps2 = 1 / epsilon^2, 0 for Saffman's limit).
inline double mclaughlin_tau_integrand(double alpha, double beta, double tau, double inv_eps2) {
  const double m = 1.0 + alpha * alpha * tau * tau / 3.0, delta = alpha * beta * tau;
  const double pp = m + delta, pm = m - delta;
  const double c = alpha * alpha * tau * inv_eps2;
  const double xp = c / pp, xm = c / pm;
  const double xmid = 0.5 * (xp + xm), xhalf = -c * delta / (pp * pm);  // (xp - xm) / 2
  const double ep = (2.0 - xp) * std::exp(-0.25 * xp), em = (2.0 - xm) * std::exp(-0.25 * xm);
  // E(xmid + h) - E(xmid - h), written without the difference
  const double de = -2.0 * std::exp(-0.25 * xmid) *
                    ((2.0 - xmid) * std::sinh(0.25 * xhalf) + xhalf * std::cosh(0.25 * xhalf));
  const double sp = pp * std::sqrt(pp), sm = pm * std::sqrt(pm);
  // P+^-3/2 - P-^-3/2 = (P-^3 - P+^3) / ((P-^3/2 + P+^3/2) P+^3/2 P-^3/2), P-^3 - P+^3 = -2 delta (..)
  const double dg = -2.0 * delta * (pm * pm + pm * pp + pp * pp) / (sm + sp) / (sp * sm);
  const double diff = 0.5 * dg * (ep + em) + 0.5 * (1.0 / sp + 1.0 / sm) * de;
  const double sum = ep / sp + em / sm;
  return alpha * (beta * diff + alpha * tau * sum) / (tau * std::sqrt(tau));
}

/// McLaughlin's J(epsilon) (epsilon <= 0 or infinite: Saffman's limit J(inf)), to an absolute
/// error of about abstol.
inline double mclaughlin_j_by_quadrature(double epsilon, double abstol = 1e-9) {
  const double inv_eps2 = epsilon > 0.0 && std::isfinite(epsilon) ? 1.0 / (epsilon * epsilon) : 0.0;
  const double pi = std::acos(-1.0);
  const auto over_theta = [&](double theta) {
    const double st = std::sin(theta);
    const auto over_phi = [&](double phi) {
      const double alpha = st * std::cos(phi), beta = st * std::sin(phi);
      // tau in [0, 1] as u^2 (the tau^-1/2 end made smooth), tau in [1, inf) as 1 / v^2
      const auto near = [&](double u) {
        return u > 0.0 ? 2.0 * u * mclaughlin_tau_integrand(alpha, beta, u * u, inv_eps2) : 0.0;
      };
      const auto far = [&](double v) {
        return v > 0.0 ? 2.0 / (v * v * v) * mclaughlin_tau_integrand(alpha, beta, 1.0 / (v * v), inv_eps2)
                       : 0.0;
      };
      return gauss_kronrod(near, 0.0, 1.0, 1e-2 * abstol) + gauss_kronrod(far, 0.0, 1.0, 1e-2 * abstol);
    };
    return st * gauss_kronrod(over_phi, 0.0, 0.5 * pi, 0.1 * abstol);
  };
  return 0.25 * std::sqrt(pi) * gauss_kronrod(over_theta, 0.0, 0.5 * pi, abstol);
}

}  // namespace boycott::test
