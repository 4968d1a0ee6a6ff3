#pragma once
// The transverse force budget of the particles across the gap (output.force_budget_y): for each
// band of y, the time-averaged y-force per particle of every force the particles feel, over the
// steps it is armed for (the averaging window). It tells which force holds the particles where
// pdf_y finds them: in a steady suspension the forces of each band add up to ~0 (what is left,
// `net`, is the band's mean m dv_y/dt).
//
// Terms (N per particle, y-components), each binned at the particle's y:
//   drag               beta (u_f - v) as the implicit kicks applied it (the drag impulse / dt)
//   lift               the lift law's force (forces.lift)
//   pressure_gradient  -V_p dP/dy
//   viscous            V_p (div tau)_y
//   added_mass         (rho_f V_p / 2) (Du_f/Dt - dv/dt)
//   gravity            m g_y (zero in a vertical channel; the buoyancy is in pressure_gradient)
//   walls              the particle-wall contacts (the DEM's own sum, per force evaluation)
//   particle_contacts  the particle-particle contacts: every particle's momentum change less the
//                      terms above (the integrator's contact impulse, exact to round-off)
//   net                m dv_y/dt
// and, beside the forces, the band's mean inputs of the lift laws (lift_laws.hpp): the particle
// Reynolds number Re_p = |u_f - u_p| d / nu and the shear Reynolds number Re_w = |w| d^2 / nu.
// Fluid-side terms are read when the step's forces are set (positions at the step's start), the
// others at its end: they bin a particle where it was within one step (~0.01 mm).
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "stats/running.hpp"

namespace boycott::particles {
struct ParticleStore;
}

namespace boycott::coupling {

class ForceBudget {
 public:
  enum Term {
    drag,
    lift,
    pressure_gradient,
    viscous,
    added_mass,
    gravity,
    walls,
    particle_contacts,
    net,
    kForces,  // the forces above; the lift law's inputs below
    re_p = kForces,
    re_w,
    kTerms
  };
  static constexpr std::array<const char*, kTerms> kNames = {
      "drag",    "lift",  "pressure_gradient", "viscous", "added_mass",
      "gravity", "walls", "particle_contacts", "net",     "re_p",
      "re_w"};

  /// Bands over [y0, y0 + width) m.
  ForceBudget(double y0_m, double width_m, int bands);

  /// A step's fluid forces, per particle (N) at its y (m), or a lift input: set when the step's
  /// forces are, kept until commit.
  void add_prepared(Term t, double y_m, double force_n) { prepared_[t].add(y_m, force_n); }
  /// The step of dt_s is done: the prepared forces times dt_s, and the end-of-step terms from
  /// the particles (v0: velocity at the step's start; drag_j: the drag impulse of the step).
  /// walls must already hold this step's wall impulses (the DEM adds them).
  void commit(const particles::ParticleStore& s, double dt_s, double gravity_y_m_s2);

  /// Impulse sums (N s) per band, the walls' as the DEM adds them.
  stats::Histogram& impulses(Term t) { return impulse_[t]; }
  /// Particle-seconds per band: the exposure each term's mean is over.
  const stats::Histogram& exposure() const { return exposure_; }

  /// Every histogram (exposure first, then the terms), for checkpoints and sums over ranks.
  std::vector<stats::Histogram*> all();
  /// The CSV: y_m, particle_density (1/m, the time-weighted pdf of y), then each force's mean
  /// per particle (N), the same divided by the buoyant weight w_b (N) in *_per_weight, and the
  /// band's mean Re_p and Re_w.
  std::string csv(double buoyant_weight_n) const;

 private:
  stats::Histogram exposure_;
  std::vector<stats::Histogram> impulse_, prepared_;
};

}  // namespace boycott::coupling
