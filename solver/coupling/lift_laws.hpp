#pragma once
// Shear lift laws (forces.lift). Each is Saffman's force (Eq. 16 of the paper),
//   F_L = 1.61 rho_f d^2 sqrt(nu / |w|) (u_f - u_p) x w,
// times a factor f(Re_p, Re_w) of the particle Reynolds number Re_p = |u_f - u_p| d / nu and the
// shear Reynolds number Re_w = |w| d^2 / nu (w: the fluid vorticity at the particle, 1/s):
//
//   saffman      f = 1. Saffman (1965, 1968): unbounded linear shear, Re_p << Re_w^(1/2) << 1.
//   saffman_mei  Mei (1992), Int. J. Multiphase Flow 18, 145, eq. (8), a fit to Dandy & Dwyer's
//                (1990) finite-Re computations, with beta = Re_w / (2 Re_p):
//                  f = (1 - 0.3314 beta^1/2) exp(-Re_p / 10) + 0.3314 beta^1/2   (Re_p <= 40)
//                  f = 0.0524 (beta Re_p)^1/2                                    (Re_p > 40)
//                fitted over 0.1 <= Re_p <= 100 and 0.005 <= beta <= 0.4; it falls to ~0.1-0.3 of
//                Saffman's at the Re_p of 20-50 of a proppant suspension. The fit jumps down at
//                Re_p = 40 by (1 - 0.3314 beta^1/2) e^-4 (~0.016 of Saffman's, 12 % of the factor
//                at beta 0.13): its high branch starts at the low branch's asymptote, 0.0524
//                sqrt(40) = 0.3314, not at the low branch's value.
//   saffman_mei_continuous
//                Mei's fit without the jump, to measure what the jump does: the low branch up to
//                Re_p = 40 and max(low, high) above, i.e. the low branch until the rising high
//                branch meets it (Re_p ~46 at beta 0.13, 44-55 over 0.4 >= beta >= 0.005), then
//                Mei's high branch. Continuous, never below Mei's, equal to it outside 40-55.
//   mclaughlin   McLaughlin (1991), J. Fluid Mech. 224, 261: f = J(epsilon) / J(inf), epsilon =
//                Re_w^1/2 / Re_p = (|w| nu)^1/2 / |u_f - u_p|. Saffman's analysis with the slip's
//                inertia kept beside the shear's: Re_p << 1 and Re_w << 1, epsilon free (Saffman's
//                law is epsilon -> inf). J falls from J(inf) as 0.66 / epsilon^2, is 0.75 of it at
//                epsilon = 1, changes sign at epsilon = 0.222 and tends to -32 pi^2 epsilon^5
//                ln(epsilon^-2) (a lift toward the slower fluid, at most 0.0074 of Saffman's, at
//                epsilon 0.18). J is the table below, interpolated (mclaughlin_j).
//   none         no lift.
//
// Neither law knows about walls: within a Saffman length sqrt(nu / |w|) of a wall the lift of a
// wall-bounded shear differs (McLaughlin 1993; Cherukat & McLaughlin 1994), and no published law
// covers Re_p 20-50 there (docs/validation.md, "Across the gap").
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::coupling {

enum class LiftLaw { saffman, saffman_mei, saffman_mei_continuous, mclaughlin, none };

inline LiftLaw lift_law_from_name(const std::string& s) {
  if (s == "saffman") return LiftLaw::saffman;
  if (s == "saffman_mei") return LiftLaw::saffman_mei;
  if (s == "saffman_mei_continuous") return LiftLaw::saffman_mei_continuous;
  if (s == "mclaughlin") return LiftLaw::mclaughlin;
  if (s == "none") return LiftLaw::none;
  throw InputError(fmt::format("forces.lift = \"{}\": not a lift law of the coupling", s));
}

/// Mei's (1992) ratio of the finite-Re lift to Saffman's; re_p > 0, re_w >= 0.
namespace mei {
/// Mei's fit below Re_p = 40, at beta = Re_w / (2 Re_p); it tends to 0.3314 beta^1/2.
inline double low_branch(double re_p, double beta) {
  const double a = 0.3314 * std::sqrt(beta);
  return (1.0 - a) * std::exp(-0.1 * re_p) + a;
}
/// Mei's fit above Re_p = 40.
inline double high_branch(double re_p, double beta) {
  return 0.0524 * std::sqrt(beta * re_p);
}
}  // namespace mei

inline double mei_lift_factor(double re_p, double re_w) {
  const double beta = 0.5 * re_w / re_p;
  return re_p <= 40.0 ? mei::low_branch(re_p, beta) : mei::high_branch(re_p, beta);
}

/// Mei's ratio with its jump at Re_p = 40 bridged (saffman_mei_continuous): the low branch until
/// the high branch rises above it; re_p > 0, re_w >= 0.
inline double mei_continuous_lift_factor(double re_p, double re_w) {
  const double beta = 0.5 * re_w / re_p;
  const double low = mei::low_branch(re_p, beta);
  return re_p <= 40.0 ? low : std::max(low, mei::high_branch(re_p, beta));
}

/// McLaughlin's (1991) J(epsilon) as a table over log10 epsilon = -1.6 (epsilon 0.0251) to 2
/// (epsilon 100) in steps of 0.05, and J(inf). McLaughlin printed J at a few epsilon; his table
/// was not to be found here, so these values are his J computed anew: the quadrature of his and
/// Saffman's outer problem in tests/unit/coupling/mclaughlin_quadrature.hpp (to 1e-9), which
/// reproduces his limits (J(inf): Saffman's 6.46 pi / 9 = 2.255 to the three figures printed;
/// -32 pi^2 epsilon^5 ln(epsilon^-2) at small epsilon) and which test_mclaughlin_table.cpp
/// reprints.
namespace mclaughlin {
inline constexpr double kLog10EpsilonFirst = -1.6;
inline constexpr double kLog10EpsilonStep = 0.05;
inline constexpr double kJInfinity = 2.253577572;
inline constexpr std::array<double, 73> kJ = {
    -0.000013568, -0.000022832, -0.000038295, -0.000063992, -0.000106478, -0.000176300, -0.000290217,
    -0.000474442, -0.000769107, -0.001233837, -0.001953422, -0.003040412, -0.004627187, -0.006832762,
    -0.009679955, -0.012931472, -0.015820770, -0.016690247, -0.012617617, 0.000814632,  0.029395535,
    0.079564060,  0.156964519,  0.264605125,  0.401457039,  0.562279951,  0.738771960,  0.921439616,
    1.101391658,  1.271535681,  1.427058904,  1.565347374,  1.685587344,  1.788260129,  1.874665353,
    1.946536073,  2.005760728,  2.054201023,  2.093585012,  2.125453854,  2.151143994,  2.171790936,
    2.188344887,  2.201591889,  2.212176466,  2.220623506,  2.227358208,  2.232723591,  2.236995475,
    2.240395083,  2.243099488,  2.245250202,  2.246960172,  2.248319457,  2.249399813,  2.250258372,
    2.250940604,  2.251482680,  2.251913367,  2.252255538,  2.252527374,  2.252743327,  2.252914880,
    2.253051160,  2.253159417,  2.253245413,  2.253313724,  2.253367988,  2.253411091,  2.253445331,
    2.253472528,  2.253494132,  2.253511293,
};

/// dJ / d(log10 epsilon) at the nodes: zero where the neighbouring secants differ in sign, their
/// harmonic mean elsewhere (Fritsch & Butland 1984), one-sided at the ends. The cubic Hermite
/// interpolant through them is monotone wherever the table is, and puts no extremum (no wiggle)
/// between two nodes.
constexpr std::array<double, kJ.size()> tangents() {
  std::array<double, kJ.size()> m{};
  const auto secant = [](std::size_t k) { return (kJ[k + 1] - kJ[k]) / kLog10EpsilonStep; };
  m.front() = secant(0);
  m.back() = secant(kJ.size() - 2);
  for (std::size_t k = 1; k + 1 < kJ.size(); ++k) {
    const double a = secant(k - 1), b = secant(k);
    m[k] = a * b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
  }
  return m;
}
inline constexpr std::array<double, kJ.size()> kDJ = tangents();
/// J(inf) - J -> C / epsilon^2 at large epsilon, C from the last node: 0.6628, where the
/// large-epsilon form quoted from McLaughlin (his eq. 3.26 in CFDEMcoupling's MeiLift) has 0.6463.
inline constexpr double kLargeEpsilonC = (kJInfinity - kJ.back()) * 1.0e4;
}  // namespace mclaughlin

/// McLaughlin's J(epsilon), epsilon >= 0: the table's monotone cubic in log10 epsilon; above it
/// (epsilon > 100) J(inf) - C / epsilon^2, below it (epsilon < 0.0251) his small-epsilon form
/// -32 pi^2 epsilon^5 (ln epsilon^-2 + k), k (= -3.07) set by the first node. Both continuous.
inline double mclaughlin_j(double epsilon) {
  namespace m = mclaughlin;
  constexpr double eps_last = 100.0;
  if (epsilon >= eps_last) return m::kJInfinity - m::kLargeEpsilonC / (epsilon * epsilon);
  if (!(epsilon > 0.0)) return 0.0;
  const double x = (std::log10(epsilon) - m::kLog10EpsilonFirst) / m::kLog10EpsilonStep;
  if (x <= 0.0) {
    constexpr double lead = -32.0 * 9.869604401089358;  // -32 pi^2
    constexpr double eps0_5 = 1.0e-8;                   // (10^-1.6)^5
    const double log0 = 3.2 * 2.302585092994046;        // ln(epsilon_0^-2)
    const double k = m::kJ.front() / (lead * eps0_5) - log0;
    const double e2 = epsilon * epsilon;
    return lead * e2 * e2 * epsilon * (-std::log(e2) + k);
  }
  const std::size_t i = std::min(static_cast<std::size_t>(x), m::kJ.size() - 2);
  const double t = x - static_cast<double>(i), u = 1.0 - t, h = m::kLog10EpsilonStep;
  return (1.0 + 2.0 * t) * u * u * m::kJ[i] + t * u * u * h * m::kDJ[i] +
         t * t * (3.0 - 2.0 * t) * m::kJ[i + 1] - t * t * u * h * m::kDJ[i + 1];
}

/// McLaughlin's (1991) ratio of the lift to Saffman's, J(epsilon) / J(inf) with epsilon =
/// Re_w^1/2 / Re_p; re_p > 0, re_w >= 0. Negative for epsilon < 0.222.
inline double mclaughlin_lift_factor(double re_p, double re_w) {
  return mclaughlin_j(std::sqrt(re_w) / re_p) / mclaughlin::kJInfinity;
}

/// The lift of law `law` on a sphere of diameter d (m) at slip s = u_f - u_p (m/s) in vorticity
/// w (1/s), fluid density rho (kg/m^3) and kinematic viscosity nu (m^2/s), into f (N). Zero where
/// the vorticity or the slip is zero.
inline void lift_force(LiftLaw law, const double (&s)[3], const double (&w)[3], double d, double rho,
                       double nu, double (&f)[3]) {
  f[0] = f[1] = f[2] = 0.0;
  if (law == LiftLaw::none) return;
  const double wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (wn <= 0.0) return;
  double c = 1.61 * rho * d * d * std::sqrt(nu / wn);
  if (law != LiftLaw::saffman) {
    const double sn = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (sn <= 0.0) return;
    const double re_p = sn * d / nu, re_w = wn * d * d / nu;
    c *= law == LiftLaw::saffman_mei              ? mei_lift_factor(re_p, re_w)
         : law == LiftLaw::saffman_mei_continuous ? mei_continuous_lift_factor(re_p, re_w)
                                                  : mclaughlin_lift_factor(re_p, re_w);
  }
  f[0] = c * (s[1] * w[2] - s[2] * w[1]);
  f[1] = c * (s[2] * w[0] - s[0] * w[2]);
  f[2] = c * (s[0] * w[1] - s[1] * w[0]);
}

}  // namespace boycott::coupling
