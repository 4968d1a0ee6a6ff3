#pragma once
// Drag laws. Each is a small type with one method,
//   double beta(alpha_f, slip_m_s, diameter_m, rho_f_kg_m3, mu_pa_s)  ->  kg/s,
// such that the drag on one particle is F = beta (u_f - u_p). Writing every law as a linear
// coefficient lets both the particle update and the fluid momentum matrix treat drag implicitly
// (docs/model.md: stiff drag). Hot loops get the law as a template parameter through
// visit_drag_law, so there is no virtual call per particle.
#include <cmath>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"

namespace boycott::coupling {

/// Di Felice's drag exactly as printed in Zeng et al. (2021), Eqs. 12-15:
///   F = (1/2) pi r^2 rho_f C_d |s| s,  Re = d |s| / nu_f,
///   C_d = (24/Re) (8.33 a_p/a_f + 0.0972 Re)        for a_f < 0.8   (Ergun form)
///   C_d = (24/Re) f_base a_f^-zeta                   otherwise       (Di Felice 1994)
///   f_base = 1 + 0.167 Re^0.687 (Re < 1000), 0.0183 Re otherwise
///   zeta = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2).
/// With (1/2) pi r^2 rho C_d |s| = 3 pi mu d (C_d Re / 24), beta = 3 pi mu d (C_d Re / 24), which
/// stays finite as Re -> 0 (zeta is then evaluated at a tiny Re, where it tends to 3.7).
struct DragDiFelicePaper {
  static constexpr const char* name = "difelice_paper";
  double beta(double alpha_f, double slip, double d, double rho_f, double mu) const {
    const double re = rho_f * d * slip / mu;
    const double stokes = 3.0 * kPi * mu * d;  // kg/s
    if (alpha_f < 0.8) return stokes * (8.33 * (1.0 - alpha_f) / alpha_f + 0.0972 * re);
    const double f_base = re < 1000.0 ? 1.0 + 0.167 * std::pow(re, 0.687) : 0.0183 * re;
    const double lg = std::log10(std::max(re, 1e-300));
    const double zeta = 3.7 - 0.65 * std::exp(-0.5 * (1.5 - lg) * (1.5 - lg));
    return stokes * f_base * std::pow(alpha_f, -zeta);
  }
};

/// Di Felice (1994) in its original form (Int. J. Multiphase Flow 20, 153), where the particle
/// Reynolds number carries the fluid fraction and the single-sphere coefficient is Dallavalle's:
///   F = (1/2) C_d0 rho_f pi r^2 eps^(2 - chi) |s| s,   eps = alpha_f,
///   Re_s = rho_f d eps |s| / mu,   C_d0 = (0.63 + 4.8 / Re_s^0.5)^2,
///   chi = 3.7 - 0.65 exp(-(1.5 - log10 Re_s)^2 / 2)   (Eq. 15 of Zeng et al. with Re_s).
/// beta = F / s = (1/2) C_d0 rho_f pi r^2 eps^(2 - chi) |s|; with C_d0 |s| -> (4.8)^2 mu /
/// (rho_f d eps) as Re_s -> 0 it stays finite: beta -> (4.8^2 / 8) pi mu d eps^(1 - chi).
/// (Zeng et al. print instead C_d = (24 / Re) f_base alpha_f^-zeta with Re = d |s| / nu: "difelice_paper".)
struct DragDiFelice {
  static constexpr const char* name = "difelice";
  double beta(double alpha_f, double slip, double d, double rho_f, double mu) const {
    const double eps = alpha_f;
    const double re = rho_f * d * eps * slip / mu;
    const double lg = std::log10(std::max(re, 1e-300));
    const double chi = 3.7 - 0.65 * std::exp(-0.5 * (1.5 - lg) * (1.5 - lg));
    // (1/2) C_d0 rho pi r^2 |s| written as (pi d / 8) mu / eps (0.63 sqrt(Re_s) + 4.8)^2, finite at Re_s = 0
    const double sr = std::sqrt(re);
    const double cd_s = (0.63 * sr + 4.8) * (0.63 * sr + 4.8) * mu / (rho_f * d * eps);  // C_d0 |s|
    return 0.5 * cd_s * rho_f * kPi * 0.25 * d * d * std::pow(eps, 2.0 - chi);
  }
};

/// Schiller-Naumann (1933) for an isolated sphere, no voidage correction.
struct DragSchillerNaumann {
  static constexpr const char* name = "schiller_naumann";
  double beta(double /*alpha_f*/, double slip, double d, double rho_f, double mu) const {
    const double re = rho_f * d * slip / mu;
    const double stokes = 3.0 * kPi * mu * d;
    return re < 1000.0 ? stokes * (1.0 + 0.15 * std::pow(re, 0.687)) : stokes * 0.44 * re / 24.0;
  }
};

/// Stokes drag 3 pi mu d (creeping flow; verification).
struct DragStokes {
  static constexpr const char* name = "stokes";
  double beta(double, double, double d, double, double mu) const { return 3.0 * kPi * mu * d; }
};

/// No drag (the force is left out).
struct DragNone {
  static constexpr const char* name = "none";
  double beta(double, double, double, double, double) const { return 0.0; }
};

/// Calls f(law) with the law named `name` (the case key forces.drag).
template <class F>
decltype(auto) visit_drag_law(const std::string& name, F&& f) {
  if (name == DragDiFelicePaper::name) return f(DragDiFelicePaper{});
  if (name == DragDiFelice::name) return f(DragDiFelice{});
  if (name == DragSchillerNaumann::name) return f(DragSchillerNaumann{});
  if (name == DragStokes::name) return f(DragStokes{});
  if (name == DragNone::name) return f(DragNone{});
  throw InputError(fmt::format("forces.drag = \"{}\" is not a known drag law", name));
}

/// Terminal slip speed (m/s) of a sphere under the law: beta(s) s = (rho_p - rho_f) V_p g,
/// found by bisection (beta(s) s increases with s for every law above). Returns 0 when the
/// particle is neutrally buoyant or g = 0.
template <class Law>
double terminal_slip_speed(const Law& law, double alpha_f, double d, double rho_p, double rho_f, double mu,
                           double g) {
  const double weight = std::abs(rho_p - rho_f) * kPi * d * d * d / 6.0 * g;  // N
  if (weight <= 0.0) return 0.0;
  double lo = 0.0, hi = 1e-3;
  while (law.beta(alpha_f, hi, d, rho_f, mu) * hi < weight) {
    hi *= 2.0;
    if (hi > 1e6) throw PhysicsError("terminal velocity above 1e6 m/s: check the drag law parameters");
  }
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (law.beta(alpha_f, mid, d, rho_f, mu) * mid < weight ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace boycott::coupling
