// The contact forces of one DEM step: which listed pairs overlap (a branch-free first pass),
// then each contact's force and torques through the stateless kernels of contact_kernels.hpp,
// then the walls. Contact histories are kept by contact_history.cpp.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <type_traits>
#include <utility>

#include "core/timers.hpp"
#include "particles/contact_kernels.hpp"
#include "particles/dem_system.hpp"
#include "particles/flag_compress.hpp"
#include "particles/min_image.hpp"

namespace boycott::particles {

namespace {
/// First pass of the force loop: appends (i, list slot) of each overlapping list pair to ci, cp
/// and returns their number. The test runs over the flat pair arrays (pair_i, nb) so that it
/// vectorises (gathers) into a byte per pair; the append is a second pass (flag_compress.hpp).
/// The periodic directions are template flags so that the loop body has no branch at all; so is
/// UR, all radii equal (their sum rsum_u then replaces two gathers per pair).
template <bool PX, bool PY, bool PZ, bool UR>
std::size_t find_contacts(std::size_t np, const std::uint32_t* __restrict pair_i,
                          const std::uint32_t* __restrict nb, const double* __restrict x,
                          const double* __restrict y, const double* __restrict z,
                          const double* __restrict rad, double rsum_u, const std::array<double, 3>& len,
                          std::uint8_t* __restrict flag, std::uint32_t* __restrict ci,
                          std::uint32_t* __restrict cp) {
  const double Lx = len[0], Ly = len[1], Lz = len[2];
  const double iLx = 1.0 / Lx, iLy = 1.0 / Ly, iLz = 1.0 / Lz;
  for (std::size_t p = 0; p < np; ++p) {
    const std::uint32_t i = pair_i[p], j = nb[p];
    double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
    if constexpr (PX) dx = min_image(dx, Lx, iLx);
    if constexpr (PY) dy = min_image(dy, Ly, iLy);
    if constexpr (PZ) dz = min_image(dz, Lz, iLz);
    double rsum = rsum_u;
    if constexpr (!UR) rsum = rad[i] + rad[j];
    flag[p] = dx * dx + dy * dy + dz * dz < rsum * rsum;
  }
  return compress_flagged(np, flag, pair_i, ci, cp);
}

/// The particles [0, n) closer to wall W than their radius, appended to wc; returns their number.
/// Like find_contacts: a branch-free test into a byte per particle (vectorised), then the
/// append. A wall normal to a coordinate axis (every wall of the scenes) reads that coordinate
/// only: (x - px) 0 + (y - py) ny + (z - pz) 0 is (y - py) ny for finite coordinates, up to the
/// sign of a zero, which neither the test nor the overlap r - dist sees.
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

using FindContactsFn = std::size_t (*)(std::size_t, const std::uint32_t*, const std::uint32_t*, const double*,
                                       const double*, const double*, const double*, double,
                                       const std::array<double, 3>&, std::uint8_t*, std::uint32_t*,
                                       std::uint32_t*);
// Indexed by periodic x | y << 1 | z << 2 | uniform radii << 3.
constexpr auto kFindContacts = []<std::size_t... B>(std::index_sequence<B...>) {
  return std::array<FindContactsFn, sizeof...(B)>{
      find_contacts<(B & 1) != 0, (B & 2) != 0, (B & 4) != 0, (B & 8) != 0>...};
}
(std::make_index_sequence<16>{});
}  // namespace

template <class Rolling>
void DemSystem::compute_forces_impl(const Rolling& rolling) {
  // A fused kick has zeroed the local particles' forces and torques (kick_kick_drift); the ghost
  // copies' are zeroed here.
  const std::size_t zero_from = fused_.local_forces_zeroed ? s_.n_local : 0;
  fused_.local_forces_zeroed = false;
  for (auto* a : {&s_.fx, &s_.fy, &s_.fz, &s_.tx, &s_.ty, &s_.tz})
    std::fill(a->begin() + static_cast<std::ptrdiff_t>(zero_from), a->end(), 0.0);
  const LinearSpringDashpot& cm = cfg_.contact;
  const double kn = cm.kn_n_m, dt = cfg_.dt_s;
  const double Lx = cfg_.box.len[0], Ly = cfg_.box.len[1], Lz = cfg_.box.len[2];
  const bool px = cfg_.box.periodic[0], py = cfg_.box.periodic[1], pz = cfg_.box.periodic[2];
  double* __restrict fx = s_.fx.data();
  double* __restrict fy = s_.fy.data();
  double* __restrict fz = s_.fz.data();
  double* __restrict tx = s_.tx.data();
  double* __restrict ty = s_.ty.data();
  double* __restrict tz = s_.tz.data();
  const double* __restrict x = s_.x.data();
  const double* __restrict y = s_.y.data();
  const double* __restrict z = s_.z.data();
  // Velocities at the force time (see predict_velocities), not the half-step ones.
  const double* __restrict vx = pred_[0].data();
  const double* __restrict vy = pred_[1].data();
  const double* __restrict vz = pred_[2].data();
  const double* __restrict wx = pred_[3].data();
  const double* __restrict wy = pred_[4].data();
  const double* __restrict wz = pred_[5].data();
  // Rolling resistance acts on the actual half-step spin, which the coming kicks update.
  const double* __restrict spx = s_.wx.data();
  const double* __restrict spy = s_.wy.data();
  const double* __restrict spz = s_.wz.data();
  const double inv_dt = 1.0 / dt;
  const double* __restrict rad = s_.radius.data();
  const double* __restrict mass = s_.mass.data();
  const double* __restrict inertia = s_.inertia.data();
  std::int64_t contacts = 0;
  const bool uniform = uniform_.mass_kg > 0.0;
  const double gn_pair = cm.gamma_n(0.5 * uniform_.mass_kg), gn_wall = cm.gamma_n(uniform_.mass_kg);

  // Pass 1: which list pairs overlap. In a suspension most list pairs (8 in 9 on the LIGGGHTS
  // bench) are apart, so this is a short branch-free loop that only appends the pair to the
  // contact list; the contact work below then runs without mispredicted branches.
  const std::uint32_t* __restrict nb = verlet_.list.neighbors.data();
  const std::size_t np = verlet_.list.pair_count();
  pairs_.row.resize(np);
  pairs_.slot.resize(np);
  std::uint32_t* __restrict ci = pairs_.row.data();
  std::uint32_t* __restrict cp = pairs_.slot.data();
  // Equal radii (and moments of inertia): the usual monodisperse case, where the loops below take
  // them as constants (the same values, so the same bits) instead of gathering them per pair.
  const double Ru = uniform_.radius_m, Iu = uniform_.inertia_kg_m2;
  const bool same_r = Ru > 0.0;
  const int variant = (px ? 1 : 0) | (py ? 2 : 0) | (pz ? 4 : 0) | (same_r ? 8 : 0);
  pairs_.flag.resize(np);
  const std::size_t nc = kFindContacts[variant](np, verlet_.row_of_slot.data(), nb, x, y, z, rad, Ru + Ru,
                                                cfg_.box.len, pairs_.flag.data(), ci, cp);
  pairs_.springs.carry_to_contacts(cp, nc);
  contacts = static_cast<std::int64_t>(nc);

  // Pass 2a: each contact's force and torques, written per contact. Each contact has its own
  // history (they do not alias) and nothing is accumulated per particle here, so
  // the loop has no dependence between iterations and vectorises over contacts (gathers).
  // Pass 2b adds them to the particles. Both run on one block of contacts at a time, so the
  // per-contact results stay in L1 instead of a round trip of 9 doubles per contact through
  // memory; the additions keep contact order, so the sums are the same bits as with one pass
  // over all contacts.
  constexpr std::size_t kBlock = 256;
  pairs_.block_out.resize(9 * kBlock);
  double* __restrict oFx = pairs_.block_out.data();
  double* __restrict oFy = oFx + kBlock;
  double* __restrict oFz = oFy + kBlock;
  double* __restrict oTix = oFz + kBlock;
  double* __restrict oTiy = oTix + kBlock;
  double* __restrict oTiz = oTiy + kBlock;
  double* __restrict oTjx = oTiz + kBlock;
  double* __restrict oTjy = oTjx + kBlock;
  double* __restrict oTjz = oTjy + kBlock;
  double* __restrict hist = pairs_.springs.data();  // per contact, in contact order
  const double iLx = 1.0 / Lx, iLy = 1.0 / Ly, iLz = 1.0 / Lz;
  // The period of each direction, 0 where it is not periodic (min_image then leaves d as it is):
  // a select on the loop-invariant flag would keep the loop from vectorising.
  const double Pxl = px ? Lx : 0.0, Pyl = py ? Ly : 0.0, Pzl = pz ? Lz : 0.0;
  const double damping_factor = cm.damping_factor;
  // Equal masses (the usual case) and mixed ones are separate loops: a select between them would
  // turn the mass loads into masked gathers, which do not vectorise.
  const double Ru_over_Iu = same_r ? Ru / Iu : 0.0;
  auto contact_loop = [&](auto uniform_masses, auto uniform_radii, std::size_t k0, std::size_t k1) {
    constexpr bool UR = decltype(uniform_radii)::value;
#pragma GCC ivdep
    for (std::size_t k = k0; k < k1; ++k) {
      const std::uint32_t i = ci[k], p = cp[k], j = nb[p];
      const double mi = mass[i], mj = mass[j];
      double ri = Ru, rj = Ru;
      if constexpr (!UR) ri = rad[i], rj = rad[j];
      double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      dx = min_image(dx, Pxl, iLx);
      dy = min_image(dy, Pyl, iLy);
      dz = min_image(dz, Pzl, iLz);
      const double rsum = ri + rj;
      const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double inv = 1.0 / r;
      const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
      // (R_i w_i + R_j w_j) x n: surface velocities of the two spheres at the contact point.
      const double cx = ri * wx[i] + rj * wx[j], cy = ri * wy[i] + rj * wy[j], cz = ri * wz[i] + rj * wz[j];
      const double vrx = vx[i] - vx[j] - (cy * nz - cz * ny);
      const double vry = vy[i] - vy[j] - (cz * nx - cx * nz);
      const double vrz = vz[i] - vz[j] - (cx * ny - cy * nx);
      // gamma_n needs sqrt(m_eff k_n): a constant when all masses are equal (the usual case).
      double gn = gn_pair;
      if constexpr (!decltype(uniform_masses)::value)
        gn = damping_factor * std::sqrt(mi * mj / (mi + mj) * kn);
      double ftx, fty, ftz;
      const double fn = spring_dashpot(cm, dt, nx, ny, nz, rsum - r, vrx, vry, vrz, gn, hist[3 * k],
                                       hist[3 * k + 1], hist[3 * k + 2], ftx, fty, ftz);
      oFx[k - k0] = fn * nx + ftx;
      oFy[k - k0] = fn * ny + fty;
      oFz[k - k0] = fn * nz + ftz;
      // Torque -R n x F_t on both spheres (the arm of j is +R_j n, its force -F_t).
      const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
      double rtx = 0.0, rty = 0.0, rtz = 0.0;
      if constexpr (Rolling::enabled) {
        double ai = Ru_over_Iu, aj = Ru_over_Iu;  // R / I of each sphere, 1/(kg m)
        if constexpr (!UR) ai = ri / inertia[i], aj = rj / inertia[j];
        rolling_resistance(spx[i] - spx[j], spy[i] - spy[j], spz[i] - spz[j], nx, ny, nz, mx, my, mz, ai, aj,
                           inv_dt, rolling.mu_r * std::abs(fn), rtx, rty, rtz);
      }
      oTix[k - k0] = -ri * mx - ri * rtx;
      oTiy[k - k0] = -ri * my - ri * rty;
      oTiz[k - k0] = -ri * mz - ri * rtz;
      oTjx[k - k0] = -rj * mx + rj * rtx;
      oTjy[k - k0] = -rj * my + rj * rty;
      oTjz[k - k0] = -rj * mz + rj * rtz;
    }
  };
  for (std::size_t k0 = 0; k0 < nc; k0 += kBlock) {
    const std::size_t k1 = std::min(nc, k0 + kBlock);
    if (uniform && same_r)
      contact_loop(std::true_type{}, std::true_type{}, k0, k1);
    else if (uniform)
      contact_loop(std::true_type{}, std::false_type{}, k0, k1);
    else if (same_r)
      contact_loop(std::false_type{}, std::true_type{}, k0, k1);
    else
      contact_loop(std::false_type{}, std::false_type{}, k0, k1);
    // Pass 2b: add them to the particles, in contact order.
    for (std::size_t k = k0; k < k1; ++k) {
      const std::uint32_t i = ci[k], j = nb[cp[k]];
      const std::size_t b = k - k0;
      fx[i] += oFx[b];
      fy[i] += oFy[b];
      fz[i] += oFz[b];
      fx[j] -= oFx[b];
      fy[j] -= oFy[b];
      fz[j] -= oFz[b];
      tx[i] += oTix[b];
      ty[i] += oTiy[b];
      tz[i] += oTiz[b];
      tx[j] += oTjx[b];
      ty[j] += oTjy[b];
      tz[j] += oTjz[b];
    }
  }

  // Walls: a sphere of infinite mass at rest; history per particle and wall. As for pairs: find
  // the particles that touch the wall, reset the springs of those that have left it, then a
  // vectorisable loop over the touching ones (each particle once per wall: no conflicts).
  // Local particles only: a ghost's wall contact is its own rank's.
  const std::size_t nloc = s_.n_local;
  walls_.found.resize(nloc);
  walls_.flag.resize(nloc);
  walls_.touching.resize(cfg_.walls.size());
  std::uint32_t* __restrict wc = walls_.found.data();
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const PlaneWall& W = cfg_.walls[w];
    const double nx = W.nx, ny = W.ny, nz = W.nz, wpx = W.px, wpy = W.py, wpz = W.pz;
    double* __restrict whx = walls_.hx[w].data();
    double* __restrict why = walls_.hy[w].data();
    double* __restrict whz = walls_.hz[w].data();
    const std::size_t nw = find_wall_contacts(nloc, W, x, y, z, rad, walls_.flag.data(), wc);
    for (std::uint32_t i : walls_.touching[w]) {
      const double dist = (x[i] - wpx) * nx + (y[i] - wpy) * ny + (z[i] - wpz) * nz;
      if (dist >= rad[i]) whx[i] = why[i] = whz[i] = 0.0;
    }
    walls_.touching[w].assign(wc, wc + nw);
    contacts += static_cast<std::int64_t>(nw);
    // The force budget (off in production runs): each contact's y-force, as what the loop adds.
    std::vector<double> fy_before;
    if (wall_force_y_budget)
      for (std::size_t k = 0; k < nw; ++k) fy_before.push_back(fy[wc[k]]);
    auto wall_loop = [&](auto uniform_masses) {
#pragma GCC ivdep
      for (std::size_t k = 0; k < nw; ++k) {
        const std::uint32_t i = wc[k];
        const double ri = rad[i], mi = mass[i];
        const double dist = (x[i] - wpx) * nx + (y[i] - wpy) * ny + (z[i] - wpz) * nz;
        const double cx = ri * wx[i], cy = ri * wy[i], cz = ri * wz[i];
        const double vrx = vx[i] - (cy * nz - cz * ny);
        const double vry = vy[i] - (cz * nx - cx * nz);
        const double vrz = vz[i] - (cx * ny - cy * nx);
        double gn = gn_wall;
        if constexpr (!decltype(uniform_masses)::value) gn = damping_factor * std::sqrt(mi * kn);
        double ftx, fty, ftz;
        const double fn = spring_dashpot(cm, dt, nx, ny, nz, ri - dist, vrx, vry, vrz, gn, whx[i], why[i],
                                         whz[i], ftx, fty, ftz);
        fx[i] += fn * nx + ftx;
        fy[i] += fn * ny + fty;
        fz[i] += fn * nz + ftz;
        const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
        double rtx = 0.0, rty = 0.0, rtz = 0.0;
        if constexpr (Rolling::enabled) {
          // The wall is a sphere of infinite inertia at rest (a_j = 0).
          rolling_resistance(spx[i], spy[i], spz[i], nx, ny, nz, mx, my, mz, ri / inertia[i], 0.0, inv_dt,
                             rolling.mu_r * std::abs(fn), rtx, rty, rtz);
        }
        tx[i] += -ri * (mx + rtx);
        ty[i] += -ri * (my + rty);
        tz[i] += -ri * (mz + rtz);
      }
    };
    if (uniform)
      wall_loop(std::true_type{});
    else
      wall_loop(std::false_type{});
    if (wall_force_y_budget)
      for (std::size_t k = 0; k < nw; ++k)
        wall_force_y_budget->add(y[wc[k]], (fy[wc[k]] - fy_before[k]) * cfg_.dt_s);
  }
  counters_.contacts = contacts;
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
