// The contact forces of one DEM step: each contact's force and torques through the stateless
// kernels of contact_kernels.hpp, then the walls. Which listed pairs overlap is found by
// contact_search.cpp; contact histories are kept by contact_history.cpp.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/timers.hpp"
#include "particles/contact_kernels.hpp"
#include "particles/dem_system.hpp"
#include "particles/flag_compress.hpp"
#include "particles/min_image.hpp"

namespace boycott::particles {

namespace {
/// The particles [0, n) closer to wall W than their radius, appended to wc; returns their number.
/// Like the pair search (contact_search.cpp): a branch-free test into a byte per particle (vectorised), then
/// the append. A wall normal to a coordinate axis (every wall of the scenes) reads that coordinate only: (x -
/// px) 0 + (y - py) ny + (z - pz) 0 is (y - py) ny for finite coordinates, up to the sign of a zero, which
/// neither the test nor the overlap r - dist sees.
std::size_t find_wall_contacts(std::size_t n, const PlaneWall& W, const double* __restrict x,
                               const double* __restrict y, const double* __restrict z,
                               const double* __restrict rad, std::uint8_t* __restrict flag,
                               std::uint32_t* __restrict wc) {
  const int axis = W.nx != 0.0 && W.ny == 0.0 && W.nz == 0.0   ? 0
                   : W.nx == 0.0 && W.ny != 0.0 && W.nz == 0.0 ? 1
                   : W.nx == 0.0 && W.ny == 0.0 && W.nz != 0.0 ? 2
                                                               : -1;
  if (axis >= 0) {
    const double* __restrict c = axis == 0 ? x : axis == 1 ? y : z;
    const double p = axis == 0 ? W.px : axis == 1 ? W.py : W.pz;
    const double nrm = axis == 0 ? W.nx : axis == 1 ? W.ny : W.nz;
    for (std::size_t i = 0; i < n; ++i) flag[i] = (c[i] - p) * nrm < rad[i];
  } else {
    const double nx = W.nx, ny = W.ny, nz = W.nz, wpx = W.px, wpy = W.py, wpz = W.pz;
    for (std::size_t i = 0; i < n; ++i)
      flag[i] = (x[i] - wpx) * nx + (y[i] - wpy) * ny + (z[i] - wpz) * nz < rad[i];
  }
  return compress_flagged(n, flag, nullptr, nullptr, wc);
}

/// Contacts per block of the pair loop: its per-contact results (9 doubles each) stay in L1.
constexpr std::size_t kContactBlock = 256;

/// The per-contact results of a block of contacts in `out` (9 arrays of kContactBlock): force on
/// i (N), torques on i and on j (N m).
struct BlockResults {
  double *Fx, *Fy, *Fz, *Tix, *Tiy, *Tiz, *Tjx, *Tjy, *Tjz;
};

inline BlockResults block_results(double* out) {
  constexpr std::size_t b = kContactBlock;
  return BlockResults{out,         out + b,     out + 2 * b, out + 3 * b, out + 4 * b,
                      out + 5 * b, out + 6 * b, out + 7 * b, out + 8 * b};
}

/// The particle arrays of a force evaluation: positions, the velocities at the force time (see
/// DemSystem::predict_velocities), the half-step spin that rolling resistance acts on, the
/// properties, and the forces and torques the contacts add to.
struct ContactArrays {
  const double *x, *y, *z;
  const double *vx, *vy, *vz, *wx, *wy, *wz;
  const double *spx, *spy, *spz;
  const double *rad, *mass, *inertia;
  double *fx, *fy, *fz, *tx, *ty, *tz;
};

ContactArrays contact_arrays(ParticleStore& s, const std::vector<double> (&pred)[6]) {
  return ContactArrays{s.x.data(),     s.y.data(),     s.z.data(),      pred[0].data(), pred[1].data(),
                       pred[2].data(), pred[3].data(), pred[4].data(),  pred[5].data(), s.wx.data(),
                       s.wy.data(),    s.wz.data(),    s.radius.data(), s.mass.data(),  s.inertia.data(),
                       s.fx.data(),    s.fy.data(),    s.fz.data(),     s.tx.data(),    s.ty.data(),
                       s.tz.data()};
}

/// The contact model's constants of one evaluation, with those of equal masses and radii.
struct ContactConstants {
  const LinearSpringDashpot* cm;
  double kn_n_m, dt_s, inv_dt, damping_factor;
  /// gamma_n (kg/s) of a pair and of a wall contact when all masses are equal.
  double gn_pair, gn_wall;
  /// The period of each direction, 0 where it is not periodic (min_image then leaves d as it is):
  /// a select on the loop-invariant flag would keep the loop from vectorising.
  double period_x_m, period_y_m, period_z_m, inv_len_x, inv_len_y, inv_len_z;
  /// With equal radii: the radius (m) and R / I (1/(kg m)); otherwise 0.
  double radius_m, radius_over_inertia;
};

ContactConstants contact_constants(const DemConfig& cfg, const UniformProperties& u) {
  const LinearSpringDashpot& cm = cfg.contact;
  const double Lx = cfg.box.len[0], Ly = cfg.box.len[1], Lz = cfg.box.len[2];
  const bool px = cfg.box.periodic[0], py = cfg.box.periodic[1], pz = cfg.box.periodic[2];
  const bool same_r = u.radius_m > 0.0;
  return ContactConstants{&cm,
                          cm.kn_n_m,
                          cfg.dt_s,
                          1.0 / cfg.dt_s,
                          cm.damping_factor,
                          cm.gamma_n(0.5 * u.mass_kg),
                          cm.gamma_n(u.mass_kg),
                          px ? Lx : 0.0,
                          py ? Ly : 0.0,
                          pz ? Lz : 0.0,
                          1.0 / Lx,
                          1.0 / Ly,
                          1.0 / Lz,
                          u.radius_m,
                          same_r ? u.radius_m / u.inertia_kg_m2 : 0.0};
}

/// Pass 2a of the pair loop for contacts [k0, k1) of the contact list (ci, cp): each contact's
/// force on i and torques on i and j, written per contact into `out` (block_results).
/// Each contact has its own spring in `hist` (they do not alias) and nothing is accumulated per
/// particle here, so the loop has no dependence between iterations and vectorises over contacts
/// (gathers). Equal masses and equal radii are template flags: a select between them and the
/// mixed case would turn the loads into masked gathers, which do not vectorise.
template <bool UniformMasses, bool UniformRadii, class Rolling>
[[gnu::always_inline]] inline void pair_forces_block(const ContactArrays& a, const ContactConstants& c,
                                                     const Rolling& rolling,
                                                     const std::uint32_t* __restrict ci,
                                                     const std::uint32_t* __restrict cp,
                                                     const std::uint32_t* __restrict nb,
                                                     double* __restrict hist, double* __restrict out,
                                                     std::size_t k0, std::size_t k1) {
  const BlockResults o = block_results(out);
  const LinearSpringDashpot& cm = *c.cm;
  const double kn = c.kn_n_m, dt = c.dt_s, inv_dt = c.inv_dt, damping_factor = c.damping_factor;
  const double gn_pair = c.gn_pair, Ru = c.radius_m, Ru_over_Iu = c.radius_over_inertia;
  const double Pxl = c.period_x_m, Pyl = c.period_y_m, Pzl = c.period_z_m;
  const double iLx = c.inv_len_x, iLy = c.inv_len_y, iLz = c.inv_len_z;
#pragma GCC ivdep
  for (std::size_t k = k0; k < k1; ++k) {
    const std::uint32_t i = ci[k], p = cp[k], j = nb[p];
    const double mi = a.mass[i], mj = a.mass[j];
    double ri = Ru, rj = Ru;
    if constexpr (!UniformRadii) ri = a.rad[i], rj = a.rad[j];
    double dx = a.x[i] - a.x[j], dy = a.y[i] - a.y[j], dz = a.z[i] - a.z[j];
    dx = min_image(dx, Pxl, iLx);
    dy = min_image(dy, Pyl, iLy);
    dz = min_image(dz, Pzl, iLz);
    const double rsum = ri + rj;
    const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double inv = 1.0 / r;
    const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
    // (R_i w_i + R_j w_j) x n: surface velocities of the two spheres at the contact point.
    const double cx = ri * a.wx[i] + rj * a.wx[j], cy = ri * a.wy[i] + rj * a.wy[j],
                 cz = ri * a.wz[i] + rj * a.wz[j];
    const double vrx = a.vx[i] - a.vx[j] - (cy * nz - cz * ny);
    const double vry = a.vy[i] - a.vy[j] - (cz * nx - cx * nz);
    const double vrz = a.vz[i] - a.vz[j] - (cx * ny - cy * nx);
    // gamma_n needs sqrt(m_eff k_n): a constant when all masses are equal (the usual case).
    double gn = gn_pair;
    if constexpr (!UniformMasses) gn = damping_factor * std::sqrt(mi * mj / (mi + mj) * kn);
    double ftx, fty, ftz;
    const double fn = spring_dashpot(cm, dt, nx, ny, nz, rsum - r, vrx, vry, vrz, gn, hist[3 * k],
                                     hist[3 * k + 1], hist[3 * k + 2], ftx, fty, ftz);
    o.Fx[k - k0] = fn * nx + ftx;
    o.Fy[k - k0] = fn * ny + fty;
    o.Fz[k - k0] = fn * nz + ftz;
    // Torque -R n x F_t on both spheres (the arm of j is +R_j n, its force -F_t).
    const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
    double rtx = 0.0, rty = 0.0, rtz = 0.0;
    if constexpr (Rolling::enabled) {
      double ai = Ru_over_Iu, aj = Ru_over_Iu;  // R / I of each sphere, 1/(kg m)
      if constexpr (!UniformRadii) ai = ri / a.inertia[i], aj = rj / a.inertia[j];
      rolling_resistance(a.spx[i] - a.spx[j], a.spy[i] - a.spy[j], a.spz[i] - a.spz[j], nx, ny, nz, mx, my,
                         mz, ai, aj, inv_dt, rolling.mu_r * std::abs(fn), rtx, rty, rtz);
    }
    o.Tix[k - k0] = -ri * mx - ri * rtx;
    o.Tiy[k - k0] = -ri * my - ri * rty;
    o.Tiz[k - k0] = -ri * mz - ri * rtz;
    o.Tjx[k - k0] = -rj * mx + rj * rtx;
    o.Tjy[k - k0] = -rj * my + rj * rty;
    o.Tjz[k - k0] = -rj * mz + rj * rtz;
  }
}

/// Pass 2b: the block's per-contact results added to the particles, in contact order (so the sums
/// are the same bits as with one pass over all contacts).
[[gnu::always_inline]] inline void add_block_to_particles(const ContactArrays& a, const std::uint32_t* ci,
                                                          const std::uint32_t* cp, const std::uint32_t* nb,
                                                          double* out, std::size_t k0, std::size_t k1) {
  const BlockResults o = block_results(out);
  for (std::size_t k = k0; k < k1; ++k) {
    const std::uint32_t i = ci[k], j = nb[cp[k]];
    const std::size_t b = k - k0;
    a.fx[i] += o.Fx[b];
    a.fy[i] += o.Fy[b];
    a.fz[i] += o.Fz[b];
    a.fx[j] -= o.Fx[b];
    a.fy[j] -= o.Fy[b];
    a.fz[j] -= o.Fz[b];
    a.tx[i] += o.Tix[b];
    a.ty[i] += o.Tiy[b];
    a.tz[i] += o.Tiz[b];
    a.tx[j] += o.Tjx[b];
    a.ty[j] += o.Tjy[b];
    a.tz[j] += o.Tjz[b];
  }
}

/// The forces of one wall's nw contacts wc (each particle once: no conflicts, so the loop
/// vectorises), the wall a sphere of infinite mass at rest with a spring per particle (wh*).
template <bool UniformMasses, class Rolling>
[[gnu::always_inline]] inline void wall_forces(const ContactArrays& a, const ContactConstants& c,
                                               const Rolling& rolling, const PlaneWall& W,
                                               const std::uint32_t* __restrict wc, std::size_t nw,
                                               double* __restrict whx, double* __restrict why,
                                               double* __restrict whz) {
  const LinearSpringDashpot& cm = *c.cm;
  const double kn = c.kn_n_m, dt = c.dt_s, inv_dt = c.inv_dt, damping_factor = c.damping_factor;
  const double gn_wall = c.gn_wall;
  const double nx = W.nx, ny = W.ny, nz = W.nz, wpx = W.px, wpy = W.py, wpz = W.pz;
#pragma GCC ivdep
  for (std::size_t k = 0; k < nw; ++k) {
    const std::uint32_t i = wc[k];
    const double ri = a.rad[i], mi = a.mass[i];
    const double dist = (a.x[i] - wpx) * nx + (a.y[i] - wpy) * ny + (a.z[i] - wpz) * nz;
    const double cx = ri * a.wx[i], cy = ri * a.wy[i], cz = ri * a.wz[i];
    const double vrx = a.vx[i] - (cy * nz - cz * ny);
    const double vry = a.vy[i] - (cz * nx - cx * nz);
    const double vrz = a.vz[i] - (cx * ny - cy * nx);
    double gn = gn_wall;
    if constexpr (!UniformMasses) gn = damping_factor * std::sqrt(mi * kn);
    double ftx, fty, ftz;
    const double fn = spring_dashpot(cm, dt, nx, ny, nz, ri - dist, vrx, vry, vrz, gn, whx[i], why[i], whz[i],
                                     ftx, fty, ftz);
    a.fx[i] += fn * nx + ftx;
    a.fy[i] += fn * ny + fty;
    a.fz[i] += fn * nz + ftz;
    const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
    double rtx = 0.0, rty = 0.0, rtz = 0.0;
    if constexpr (Rolling::enabled) {
      // The wall is a sphere of infinite inertia at rest (a_j = 0).
      rolling_resistance(a.spx[i], a.spy[i], a.spz[i], nx, ny, nz, mx, my, mz, ri / a.inertia[i], 0.0, inv_dt,
                         rolling.mu_r * std::abs(fn), rtx, rty, rtz);
    }
    a.tx[i] += -ri * (mx + rtx);
    a.ty[i] += -ri * (my + rty);
    a.tz[i] += -ri * (mz + rtz);
  }
}

}  // namespace

template <class Rolling>
void DemSystem::compute_forces_impl(const Rolling& rolling) {
  zero_unspent_forces();
  const std::size_t pairs = find_pair_contacts();
  add_pair_forces(rolling, pairs);
  const std::size_t wall_contacts = add_wall_forces(rolling);
  counters_.contacts = static_cast<std::int64_t>(pairs) + static_cast<std::int64_t>(wall_contacts);
}

void DemSystem::zero_unspent_forces() {
  // A fused kick has zeroed the local particles' forces and torques (kick_kick_drift); the ghost
  // copies' are zeroed here.
  const std::size_t zero_from = fused_.local_forces_zeroed ? s_.n_local : 0;
  fused_.local_forces_zeroed = false;
  for (auto* a : {&s_.fx, &s_.fy, &s_.fz, &s_.tx, &s_.ty, &s_.tz})
    std::fill(a->begin() + static_cast<std::ptrdiff_t>(zero_from), a->end(), 0.0);
}

template <class Rolling>
void DemSystem::add_pair_forces(const Rolling& rolling, std::size_t nc) {
  // Pass 2, a block of contacts at a time, so that the per-contact results stay in L1 instead of
  // a round trip of 9 doubles per contact through memory.
  const ContactArrays a = contact_arrays(s_, pred_);
  const ContactConstants c = contact_constants(cfg_, uniform_);
  const bool uniform = uniform_.mass_kg > 0.0, same_r = uniform_.radius_m > 0.0;
  const std::uint32_t* ci = pairs_.row.data();
  const std::uint32_t* cp = pairs_.slot.data();
  const std::uint32_t* nb = verlet_.list.neighbors.data();
  double* hist = pairs_.springs.data();  // per contact, in contact order
  pairs_.block_out.resize(9 * kContactBlock);
  double* out = pairs_.block_out.data();
  for (std::size_t k0 = 0; k0 < nc; k0 += kContactBlock) {
    const std::size_t k1 = std::min(nc, k0 + kContactBlock);
    if (uniform && same_r)
      pair_forces_block<true, true>(a, c, rolling, ci, cp, nb, hist, out, k0, k1);
    else if (uniform)
      pair_forces_block<true, false>(a, c, rolling, ci, cp, nb, hist, out, k0, k1);
    else if (same_r)
      pair_forces_block<false, true>(a, c, rolling, ci, cp, nb, hist, out, k0, k1);
    else
      pair_forces_block<false, false>(a, c, rolling, ci, cp, nb, hist, out, k0, k1);
    add_block_to_particles(a, ci, cp, nb, out, k0, k1);
  }
}

template <class Rolling>
std::size_t DemSystem::add_wall_forces(const Rolling& rolling) {
  // As for pairs: find the particles that touch the wall, reset the springs of those that have
  // left it, then the touching ones. Local particles only: a ghost's wall contact is its own
  // rank's.
  const ContactArrays a = contact_arrays(s_, pred_);
  const ContactConstants c = contact_constants(cfg_, uniform_);
  const std::size_t nloc = s_.n_local;
  walls_.found.resize(nloc);
  walls_.flag.resize(nloc);
  walls_.touching.resize(cfg_.walls.size());
  std::uint32_t* wc = walls_.found.data();
  std::size_t touching = 0;
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const PlaneWall& W = cfg_.walls[w];
    double* whx = walls_.hx[w].data();
    double* why = walls_.hy[w].data();
    double* whz = walls_.hz[w].data();
    const std::size_t nw = find_wall_contacts(nloc, W, a.x, a.y, a.z, a.rad, walls_.flag.data(), wc);
    for (std::uint32_t i : walls_.touching[w]) {
      const double dist = (a.x[i] - W.px) * W.nx + (a.y[i] - W.py) * W.ny + (a.z[i] - W.pz) * W.nz;
      if (dist >= a.rad[i]) whx[i] = why[i] = whz[i] = 0.0;
    }
    walls_.touching[w].assign(wc, wc + nw);
    touching += nw;
    // The force budget (off in production runs): each contact's y-force, as what the loop adds.
    std::vector<double> fy_before;
    if (wall_force_y_budget)
      for (std::size_t k = 0; k < nw; ++k) fy_before.push_back(a.fy[wc[k]]);
    if (uniform_.mass_kg > 0.0)
      wall_forces<true>(a, c, rolling, W, wc, nw, whx, why, whz);
    else
      wall_forces<false>(a, c, rolling, W, wc, nw, whx, why, whz);
    if (wall_force_y_budget)
      for (std::size_t k = 0; k < nw; ++k)
        wall_force_y_budget->add(a.y[wc[k]], (a.fy[wc[k]] - fy_before[k]) * cfg_.dt_s);
  }
  return touching;
}

void DemSystem::compute_forces() {
  auto t0 = std::chrono::steady_clock::now();
  if (!rolling_model_enabled(cfg_.rolling_model) || cfg_.rolling_friction == 0.0)
    compute_forces_impl(RollingNone{});
  else
    compute_forces_impl(RollingConstantDirectional{cfg_.rolling_friction});
  seconds_force += seconds_since(t0);
}

}  // namespace boycott::particles
