#pragma once
// The largest CFD step at which the explicit particle-fluid exchange of a packed region stays
// stable (numerics.drag_dt_limit).
//
// Within a CFD step the particles relax towards the fluid velocity read at the step's start
// (u^n, held fixed over the DEM sub-steps, drag implicit per sub-step), under the pressure
// gradient read then too; the fluid then moves with the particles' new volume flux. Where the
// particles of a region move together with velocity v (the wall-normal mode of a bed against
// the lower wall of a 6 mm channel), continuity makes the fluid counter-flow,
// alpha_f u = -alpha_p v, u = -r v with r = alpha_p / alpha_f, and the pressure gradient that
// pushes it through the particles, alpha_f grad p = n beta (v - u), pushes each particle with
// -V_p grad p = -r (1 + r) beta v. Both read at the step's start, a particle of relaxation time
// tau = (m + m_added) / beta relaxes for x = dt / tau towards u + F / beta = -R v^n with
// R = r (2 + r) = 1 / alpha_f^2 - 1:
//     v^{n+1} = -R v^n + (1 + R) v^n e^{-x} = g v^n,   g = e^{-x} / alpha_f^2 - R.
// |g| < 1 at every x while R <= 1 (alpha_f >= 1/sqrt 2); below that it needs
//     x < ln((1 + R) / (R - 1)) = -ln(1 - 2 alpha_f^2),
// and beyond it the mode flips sign every step and grows.
//
// Measured (docs/model.md, "The packed-bed step limit"): at 10 cP, dt_cfd 1 ms, 0.6 mm sand,
// 65 deg, a bed against the lower wall flips its wall-normal mean velocity every step once it
// packs to alpha_f ~0.45 (full size: 0.42, at 2.1 s), growing ~1.05-1.1x per step, until alpha_f
// leaves (0, 1]. Without the pressure-gradient push (g = e^{-x} (1 + r) - r) that onset would lie
// at alpha_f 0.42: the push is needed to put it at 0.45, and the full model, which
// places it at 0.57, keeps the reduced box stable (alpha_f >= 0.41, |<v_p>| < 3 mm/s where
// it reached 0.9 m/s without). The bound is taken whole: the model is already on the safe side
// of both measured onsets. In 1 cP fluid tau is ten times longer: the base case's packed beds
// allow 1.3 ms, above its 1 ms step.
#include <cmath>
#include <limits>

namespace boycott::coupling {

/// The one-region model's amplification per step of the counter-flow mode (see above).
inline double counterflow_amplification(double alpha_f, double dt_over_tau) {
  return std::exp(-dt_over_tau) / (alpha_f * alpha_f) - (1.0 / (alpha_f * alpha_f) - 1.0);
}

/// Largest stable step, s, for a particle of relaxation time tau_s (s) at fluid fraction
/// alpha_f: infinity where the mode decays at any step (alpha_f >= 1/sqrt 2).
inline double drag_stable_dt_s(double alpha_f, double tau_s) {
  const double q = 1.0 - 2.0 * alpha_f * alpha_f;
  if (!(q > 0.0)) return std::numeric_limits<double>::infinity();
  return -tau_s * std::log(q);
}

}  // namespace boycott::coupling
