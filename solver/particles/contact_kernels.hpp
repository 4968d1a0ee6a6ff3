#pragma once
// Stateless contact kernels: the force arithmetic of one contact, called from the pair and wall
// loops (contact_forces.cpp) and directly by unit tests. The models' coefficients live in
// contact_models.hpp; nothing here keeps state between calls, and everything is inline so that
// the contact loops keep their registers and vectorise.
#include <cmath>
#include <limits>

#include "particles/contact_models.hpp"

namespace boycott::particles {

/// Linear spring-dashpot force on the sphere at the `n` side of a contact (n points into it),
/// overlap delta (m), relative contact velocity vr (m/s), normal damping gn (kg/s); the shear
/// spring h (m) is advanced by vt dt, turned into the current tangent plane keeping its length,
/// and capped by Coulomb (Eq. 10). Returns the signed normal force (N) and writes the
/// tangential force ft (N). A free function without captures keeps the loop's state in registers.
inline double spring_dashpot(const LinearSpringDashpot& cm, double dt, double nx, double ny, double nz,
                             double delta, double vrx, double vry, double vrz, double gn, double& hxr,
                             double& hyr, double& hzr, double& ftx, double& fty, double& ftz) {
  const double kn = cm.kn_n_m, kt = cm.kt_n_m, mu = cm.friction;
  const double gt = cm.tangential_ratio * gn;
  const double vn = vrx * nx + vry * ny + vrz * nz;
  // Selects instead of branches throughout, so that the contact loop vectorises; a factor of
  // exactly 1 where the branch was not taken leaves the same bits.
  double fn = kn * delta - gn * vn;
  // Clipping is a floor of 0 or of -infinity (no clipping): no select on a loop-invariant flag.
  fn = std::max(fn, cm.clip_attractive ? 0.0 : -std::numeric_limits<double>::infinity());
  const double vtx = vrx - vn * nx, vty = vry - vn * ny, vtz = vrz - vn * nz;
  double hx = hxr + vtx * dt, hy = hyr + vty * dt, hz = hzr + vtz * dt;
  const double hn = hx * nx + hy * ny + hz * nz;
  const double h2 = hx * hx + hy * hy + hz * hz;
  hx -= hn * nx;
  hy -= hn * ny;
  hz -= hn * nz;
  const double h2p = hx * hx + hy * hy + hz * hz;
  const double sc = h2p > 0.0 && hn != 0.0 ? std::sqrt(h2 / h2p) : 1.0;
  hx *= sc;
  hy *= sc;
  hz *= sc;
  ftx = -kt * hx - gt * vtx;
  fty = -kt * hy - gt * vty;
  ftz = -kt * hz - gt * vtz;
  const double ft2 = ftx * ftx + fty * fty + ftz * ftz;
  const double fc = mu * std::abs(fn);
  // Sliding: cap the force and reset the spring to what the capped force implies.
  const bool sliding = ft2 > fc * fc;
  const double cap = sliding ? fc / std::sqrt(ft2) : 1.0;
  ftx *= cap;
  fty *= cap;
  ftz *= cap;
  hxr = sliding ? -(ftx + gt * vtx) / kt : hx;
  hyr = sliding ? -(fty + gt * vty) / kt : hy;
  hzr = sliding ? -(ftz + gt * vtz) / kt : hz;
  return fn;
}

/// Eq. 11's cap: the rolling resistance q (per unit radius, N) is at most mu_r |F_n| in size.
inline void cap_rolling(double qx, double qy, double qz, double qmax, double& rx, double& ry, double& rz) {
  const double q2 = qx * qx + qy * qy + qz * qz;
  const double sc = q2 > qmax * qmax ? qmax / std::sqrt(q2) : 1.0;
  rx = sc * qx;
  ry = sc * qy;
  rz = sc * qz;
}

/// Rolling resistance of one contact (Eq. 11), per unit radius (N): the torques are
/// T_i = -R_i q on sphere i and +R_j q on sphere j. q is the value that, together with this
/// contact's friction torque (m = n x F_t, N), stops the relative rolling within the coming step;
/// capped at mu_r |F_n| (qmax) it is Eq. 11's constant torque along the rolling direction. Below
/// the cap the contact holds like static friction instead of flipping sign every step (chatter)
/// or creeping at O(g dt). Inputs: the relative spin w_i - w_j (rad/s), the unit normal n, the
/// friction moment m, a = R / I of each sphere (1/(kg m)); a wall is a sphere of infinite
/// inertia (a_j = 0, w_j = 0).
inline void rolling_resistance(double orx, double ory, double orz, double nx, double ny, double nz, double mx,
                               double my, double mz, double ai, double aj, double inv_dt, double qmax,
                               double& rx, double& ry, double& rz) {
  const double on = orx * nx + ory * ny + orz * nz;
  const double ik = 1.0 / (ai + aj);
  const double qx = ((orx - on * nx) * inv_dt + (aj - ai) * mx) * ik;
  const double qy = ((ory - on * ny) * inv_dt + (aj - ai) * my) * ik;
  const double qz = ((orz - on * nz) * inv_dt + (aj - ai) * mz) * ik;
  cap_rolling(qx, qy, qz, qmax, rx, ry, rz);
}

}  // namespace boycott::particles
