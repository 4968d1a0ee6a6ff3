#pragma once
// Contact sub-models: each a small type owning its coefficients, called from the pair loop
// through a template parameter (chosen once by make_contact_kernel), never through a virtual
// call per contact.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/constants.hpp"

namespace boycott::particles {

/// Linear spring-dashpot (Zeng et al. 2021 Eqs. 7-8, k_t = k_n) with Coulomb cap (Eq. 10).
///
/// Damping from the restitution coefficient e (docs/model.md, "The particle engine"; the printed Eq. 9 is
/// garbled):  gamma_n = -2 ln(e) sqrt(m_eff k_n) / sqrt(pi^2 + ln^2 e).
/// With this gamma_n the linear oscillator m_eff x'' + gamma_n x' + k_n x = 0 returns with speed
/// ratio exactly e after half a damped period, provided the contact ends when the overlap (not
/// the force) returns to zero, i.e. the normal force may turn slightly attractive at the end.
/// `clip_attractive` forbids that (F_n >= 0); the contact then lasts longer and the rebound
/// exceeds e (tests measure by how much).
struct LinearSpringDashpot {
  double kn_n_m = 3.5;
  double kt_n_m = 3.5;
  double damping_factor = 0.0;    ///< -2 ln e / sqrt(pi^2 + ln^2 e); gamma_n = factor sqrt(m_eff k_n)
  double tangential_ratio = 0.5;  ///< gamma_t / gamma_n
  double friction = 0.6;          ///< mu_s
  bool clip_attractive = false;

  LinearSpringDashpot() = default;
  LinearSpringDashpot(double kn, double e, double tang_ratio, double mu, bool clip)
      : kn_n_m(kn),
        kt_n_m(kn),
        damping_factor(restitution_damping_factor(e)),
        tangential_ratio(tang_ratio),
        friction(mu),
        clip_attractive(clip) {}

  static double restitution_damping_factor(double e) {
    const double le = std::log(e);
    return -2.0 * le / std::sqrt(kPi * kPi + le * le);
  }
  double gamma_n(double m_eff) const { return damping_factor * std::sqrt(m_eff * kn_n_m); }
  /// Contact duration pi sqrt(m_eff (1 + b^2)/k_n), b = -ln(e)/pi (unclipped).
  static double collision_time(double m_eff, double kn, double e) {
    const double b = -std::log(e) / kPi;
    return kPi * std::sqrt(m_eff * (1.0 + b * b) / kn);
  }
};

/// Constant directional rolling torque (Eq. 11): T_i = -mu_r |F_n| R_i w_t/|w_t|, w_t the relative
/// angular velocity projected on the contact plane. Near w_t = 0 a constant torque would flip
/// sign every step (chatter); the torque is therefore capped at the value that brings the
/// relative rolling to rest within one step, never reversing it.
struct RollingConstantDirectional {
  double mu_r = 0.1;
  static constexpr bool enabled = true;
};

struct RollingNone {
  static constexpr bool enabled = false;
};

/// The rolling model named in contact.rolling_model (core/model_names.hpp's list): whether
/// Eq. 11's torque is on. Throws InputError for a name not in the list.
bool rolling_model_enabled(const std::string& name);
/// Checks contact.model against the contact models this engine has (one: the linear
/// spring-dashpot above). Throws InputError for another name.
void check_contact_model(const std::string& name);

}  // namespace boycott::particles
