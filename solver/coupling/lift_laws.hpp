#pragma once
// Shear lift laws (forces.lift). Each is Saffman's force (Eq. 16 of the paper),
//   F_L = 1.61 rho_f d^2 sqrt(nu / |w|) (u_f - u_p) x w,
// times a factor f(Re_p, Re_w) >= 0 of the particle Reynolds number Re_p = |u_f - u_p| d / nu and
// the shear Reynolds number Re_w = |w| d^2 / nu (w: the fluid vorticity at the particle, 1/s):
//
//   saffman      f = 1. Saffman (1965, 1968): unbounded linear shear, Re_p << Re_w^(1/2) << 1.
//   saffman_mei  Mei (1992), Int. J. Multiphase Flow 18, 145, eq. (8), a fit to Dandy & Dwyer's
//                (1990) finite-Re computations, with beta = Re_w / (2 Re_p):
//                  f = (1 - 0.3314 beta^1/2) exp(-Re_p / 10) + 0.3314 beta^1/2   (Re_p <= 40)
//                  f = 0.0524 (beta Re_p)^1/2                                    (Re_p > 40)
//                fitted over 0.1 <= Re_p <= 100 and 0.005 <= beta <= 0.4; it falls to ~0.1-0.3 of
//                Saffman's at the Re_p of 20-50 of a proppant suspension.
//   none         no lift.
//
// Neither law knows about walls: within a Saffman length sqrt(nu / |w|) of a wall the lift of a
// wall-bounded shear differs (McLaughlin 1993; Cherukat & McLaughlin 1994), and no published law
// covers Re_p 20-50 there (docs/validation.md, "Across the gap").
#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::coupling {

enum class LiftLaw { saffman, saffman_mei, none };

inline LiftLaw lift_law_from_name(const std::string& s) {
  if (s == "saffman") return LiftLaw::saffman;
  if (s == "saffman_mei") return LiftLaw::saffman_mei;
  if (s == "none") return LiftLaw::none;
  throw InputError(fmt::format("forces.lift = \"{}\": not a lift law of the coupling", s));
}

/// Mei's (1992) ratio of the finite-Re lift to Saffman's; re_p > 0, re_w >= 0.
inline double mei_lift_factor(double re_p, double re_w) {
  const double beta = 0.5 * re_w / re_p;
  if (re_p <= 40.0) {
    const double a = 0.3314 * std::sqrt(beta);
    return (1.0 - a) * std::exp(-0.1 * re_p) + a;
  }
  return 0.0524 * std::sqrt(beta * re_p);
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
  if (law == LiftLaw::saffman_mei) {
    const double sn = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (sn <= 0.0) return;
    c *= mei_lift_factor(sn * d / nu, wn * d * d / nu);
  }
  f[0] = c * (s[1] * w[2] - s[2] * w[1]);
  f[1] = c * (s[2] * w[0] - s[0] * w[2]);
  f[2] = c * (s[0] * w[1] - s[1] * w[0]);
}

}  // namespace boycott::coupling
