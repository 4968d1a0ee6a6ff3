#include "particles/dem_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::particles {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::uint64_t pair_key(std::int64_t a, std::int64_t b) {
  return (static_cast<std::uint64_t>(a) << 32) ^ static_cast<std::uint64_t>(b);
}
}  // namespace

DemConfig DemConfig::from_case(const CaseParams& p) {
  DemConfig c;
  c.box.lo = {0.0, 0.0, 0.0};
  c.box.len = {p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m};
  c.box.periodic = {true, p.domain.periodic_y, true};
  if (!p.domain.periodic_y) {
    c.walls.push_back(PlaneWall{0.0, 0.0, 0.0, 0.0, 1.0, 0.0});
    c.walls.push_back(PlaneWall{0.0, p.domain.width_y_m, 0.0, 0.0, -1.0, 0.0});
  }
  c.gravity_m_s2 = p.gravity_vector();
  c.dt_s = p.time.dt_dem_s;
  c.skin_m = p.numerics.neighbor_skin_m;
  c.contact = LinearSpringDashpot(p.contact.stiffness_n_m, p.contact.restitution, p.contact.tangential_damping_ratio,
                                  p.contact.friction, p.contact.clip_attractive_normal);
  c.rolling_model = p.contact.rolling_model;
  c.rolling_friction = p.contact.rolling_friction;
  return c;
}

DemSystem::DemSystem(const DemConfig& cfg) : cfg_(cfg) {
  whx_.resize(cfg_.walls.size());
  why_.resize(cfg_.walls.size());
  whz_.resize(cfg_.walls.size());
}

void DemSystem::add_particle(std::int64_t gid, double x, double y, double z, double r, double rho) {
  s_.add(gid, x, y, z, r, rho);
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    whx_[w].push_back(0.0);
    why_[w].push_back(0.0);
    whz_[w].push_back(0.0);
  }
}

void DemSystem::insert_random(std::int64_t count, double r, double rho, std::array<double, 3> lo,
                              std::array<double, 3> hi, std::uint64_t seed, double gap_m) {
  // Trial placement against a uniform grid of already placed centres (cell >= 2r + gap), so
  // each trial costs O(1); bounded attempts so an overfull request fails instead of hanging.
  std::mt19937_64 rng(seed);
  const double dmin = 2.0 * r + gap_m;
  std::array<int, 3> nc;
  for (int d = 0; d < 3; ++d) nc[d] = std::max(1, static_cast<int>(cfg_.box.len[d] / dmin));
  std::vector<std::vector<std::uint32_t>> cells(static_cast<std::size_t>(nc[0]) * nc[1] * nc[2]);
  auto coord = [&](double p, int d) {
    double f = (p - cfg_.box.lo[d]) / cfg_.box.len[d];
    f -= std::floor(f);
    return std::clamp(static_cast<int>(f * nc[d]), 0, nc[d] - 1);
  };
  for (std::size_t i = 0; i < s_.size(); ++i)
    cells[coord(s_.x[i], 0) + nc[0] * (coord(s_.y[i], 1) + nc[1] * coord(s_.z[i], 2))].push_back(i);
  std::array<std::uniform_real_distribution<double>, 3> U;
  for (int d = 0; d < 3; ++d) U[d] = std::uniform_real_distribution<double>(lo[d], hi[d]);
  std::int64_t next_id = s_.size() ? *std::max_element(s_.id.begin(), s_.id.end()) + 1 : 0;
  const std::int64_t max_attempts = 2000 * count + 100000;
  std::int64_t placed = 0, attempts = 0;
  while (placed < count) {
    if (++attempts > max_attempts)
      throw InputError(fmt::format("could not insert {} particles of radius {} m without overlap after {} attempts "
                                   "({} placed): the region is too full",
                                   count, r, max_attempts, placed));
    const double p[3] = {U[0](rng), U[1](rng), U[2](rng)};
    bool ok = true;
    for (const auto& w : cfg_.walls) {
      const double dist = (p[0] - w.px) * w.nx + (p[1] - w.py) * w.ny + (p[2] - w.pz) * w.nz;
      if (dist < r + 0.5 * gap_m) ok = false;
    }
    const int c[3] = {coord(p[0], 0), coord(p[1], 1), coord(p[2], 2)};
    for (int oz = -1; oz <= 1 && ok; ++oz)
      for (int oy = -1; oy <= 1 && ok; ++oy)
        for (int ox = -1; ox <= 1 && ok; ++ox) {
          const int k[3] = {c[0] + ox, c[1] + oy, c[2] + oz};
          int kk[3];
          bool skip = false;
          for (int d = 0; d < 3; ++d) {
            kk[d] = k[d];
            if (k[d] < 0 || k[d] >= nc[d]) {
              if (!cfg_.box.periodic[d]) skip = true;
              kk[d] = (k[d] + nc[d]) % nc[d];
            }
          }
          if (skip) continue;
          for (std::uint32_t j : cells[kk[0] + nc[0] * (kk[1] + nc[1] * kk[2])]) {
            const double dx = min_image(p[0] - s_.x[j], cfg_.box.len[0], cfg_.box.periodic[0]);
            const double dy = min_image(p[1] - s_.y[j], cfg_.box.len[1], cfg_.box.periodic[1]);
            const double dz = min_image(p[2] - s_.z[j], cfg_.box.len[2], cfg_.box.periodic[2]);
            const double rr = r + s_.radius[j] + gap_m;
            if (dx * dx + dy * dy + dz * dz < rr * rr) {
              ok = false;
              break;
            }
          }
        }
    if (!ok) continue;
    cells[c[0] + nc[0] * (c[1] + nc[1] * c[2])].push_back(static_cast<std::uint32_t>(s_.size()));
    add_particle(next_id++, p[0], p[1], p[2], r, rho);
    ++placed;
  }
}

void DemSystem::initialize() {
  if (cfg_.dry)
    for (std::size_t i = 0; i < s_.size(); ++i)
      if (s_.ext_x[i] != 0.0 || s_.ext_y[i] != 0.0 || s_.ext_z[i] != 0.0 || s_.ufx[i] != 0.0 || s_.ufy[i] != 0.0 ||
          s_.ufz[i] != 0.0 || s_.madd[i] != 0.0)
        throw std::logic_error("DemConfig::dry is set but a particle has a fluid force, velocity or added mass");
  double rmax = 0.0;
  for (double r : s_.radius) rmax = std::max(rmax, r);
  cutoff_m_ = 2.0 * rmax + cfg_.skin_m;
  update_uniform_mass();
  rebuild();
  predict_velocities();
  compute_forces();
  initialized_ = true;
}

void DemSystem::update_uniform_mass() {
  uniform_mass_kg_ = s_.size() ? s_.mass[0] : 0.0;
  for (double m : s_.mass)
    if (m != uniform_mass_kg_) uniform_mass_kg_ = 0.0;
}

void DemSystem::force_rebuild() {
  // Only the list: the forces of the current positions stay valid, and evaluating them again
  // would advance the shear springs twice in one step.
  rebuild();
}

bool DemSystem::needs_rebuild() const {
  // A pair's distance changes by at most |D_i - D_j| <= |D_i - c| + |D_j - c| for any common
  // vector c, D the displacements since the last build. With c the mean displacement, a uniform
  // drift of the whole packing (a settling bed in a periodic box) does not force rebuilds, and
  // the list stays exact while every |D_i - c| < skin/2. Walls are not in the list: every
  // particle is tested against every wall each step.
  const std::size_t n = s_.size();
  if (n == 0) return false;
  double cx = 0.0, cy = 0.0, cz = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    cx += s_.x[i] - ref_x_[i];
    cy += s_.y[i] - ref_y_[i];
    cz += s_.z[i] - ref_z_[i];
  }
  const double inv = 1.0 / static_cast<double>(n);
  cx *= inv;
  cy *= inv;
  cz *= inv;
  const double lim2 = 0.25 * cfg_.skin_m * cfg_.skin_m;
  double worst = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = s_.x[i] - ref_x_[i] - cx, dy = s_.y[i] - ref_y_[i] - cy, dz = s_.z[i] - ref_z_[i] - cz;
    worst = std::max(worst, dx * dx + dy * dy + dz * dz);
  }
  return worst > lim2;
}

void DemSystem::collect_histories() {
  // Contacts with a shear history, keyed by global ids so they survive reordering and rebuilds.
  carry_a_.clear();
  carry_b_.clear();
  carry_h_.clear();
  const std::size_t n = s_.size();
  if (nl_.offsets.size() != n + 1) return;
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      if (h_[3 * p] == 0.0 && h_[3 * p + 1] == 0.0 && h_[3 * p + 2] == 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[nl_.neighbors[p]];
      const double sg = a < b ? 1.0 : -1.0;
      carry_a_.push_back(std::min(a, b));
      carry_b_.push_back(std::max(a, b));
      carry_h_.insert(carry_h_.end(), {sg * h_[3 * p], sg * h_[3 * p + 1], sg * h_[3 * p + 2]});
    }
}

void DemSystem::rebuild() {
  auto t0 = Clock::now();
  collect_histories();
  // Wrap periodic coordinates into the box, then store particles cell by cell.
  for (int d = 0; d < 3; ++d) {
    if (!cfg_.box.periodic[d]) continue;
    auto& c = d == 0 ? s_.x : (d == 1 ? s_.y : s_.z);
    const double lo = cfg_.box.lo[d], len = cfg_.box.len[d];
    for (double& v : c) v -= len * std::floor((v - lo) / len);
  }
  const auto order = nl_.bin_and_order(s_, cfg_.box, cutoff_m_);
  s_.permute(order);
  std::vector<double> tmp(order.size());
  for (auto& a : pred_) {
    if (a.size() != order.size()) continue;
    for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
    a.swap(tmp);
  }
  for (auto* wh : {&whx_, &why_, &whz_})
    for (auto& a : *wh) {
      for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
      a.swap(tmp);
    }
  nl_.build_binned(s_, cfg_.box, cutoff_m_);
  restore_histories(carry_a_, carry_b_, carry_h_);
  rescan_wall_contacts();
  ref_x_ = s_.x;
  ref_y_ = s_.y;
  ref_z_ = s_.z;
  ++rebuilds_;
  seconds_neighbor += since(t0);
}

void DemSystem::restore_histories(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                                  const std::vector<double>& h) {
  const std::size_t np = nl_.pair_count();
  h_.assign(3 * np, 0.0);
  // A new list: the pairs with a history (restored below) are the ones forget_separated_pairs
  // must look at next, and the flat row index of each slot is refreshed.
  pair_mark_.assign(np, 0);
  prev_contacts_.clear();
  pair_i_.resize(np);
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) pair_i_[p] = static_cast<std::uint32_t>(i);
  if (ida.empty()) return;
  // Sorted (key, slot) table; only pairs that overlap now can carry a history (it is reset
  // whenever a pair separates), so only those are looked up.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> table(ida.size());
  for (std::size_t q = 0; q < ida.size(); ++q) table[q] = {pair_key(ida[q], idb[q]), static_cast<std::uint32_t>(q)};
  std::sort(table.begin(), table.end());
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      const std::uint32_t j = nl_.neighbors[p];
      if (pair_overlap(i, j) <= 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[j];
      const std::uint64_t key = pair_key(std::min(a, b), std::max(a, b));
      auto it = std::lower_bound(table.begin(), table.end(), std::pair<std::uint64_t, std::uint32_t>{key, 0});
      if (it == table.end() || it->first != key) continue;
      const double sg = a < b ? 1.0 : -1.0;
      h_[3 * p] = sg * h[3 * it->second];
      h_[3 * p + 1] = sg * h[3 * it->second + 1];
      h_[3 * p + 2] = sg * h[3 * it->second + 2];
      pair_mark_[p] = 1;
      prev_contacts_.push_back(p);
    }
}

namespace {
/// Linear spring-dashpot force on the sphere at the `n` side of a contact (n points into it),
/// overlap delta (m), relative contact velocity vr (m/s), normal damping gn (kg/s); the shear
/// spring h (m) is advanced by vt dt, turned into the current tangent plane keeping its length,
/// and capped by Coulomb (Eq. 10). Returns the signed normal force (N) and writes the
/// tangential force ft (N). A free function without captures keeps the loop's state in registers.
inline double spring_dashpot(const LinearSpringDashpot& cm, double dt, double nx, double ny, double nz, double delta,
                             double vrx, double vry, double vrz, double gn, double& hxr, double& hyr, double& hzr,
                             double& ftx, double& fty, double& ftz) {
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
}  // namespace

void DemSystem::rescan_wall_contacts() {
  // After a reordering the remembered wall contacts are stale: every particle with a wall
  // history is one (the history is zero for all others).
  prev_wall_contacts_.assign(cfg_.walls.size(), {});
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w)
    for (std::size_t i = 0; i < whx_[w].size(); ++i)
      if (whx_[w][i] != 0.0 || why_[w][i] != 0.0 || whz_[w][i] != 0.0)
        prev_wall_contacts_[w].push_back(static_cast<std::uint32_t>(i));
}

void DemSystem::forget_separated_pairs(std::size_t nc) {
  // A pair's shear spring is reset when it separates (h_ is zero for every pair not in
  // contact). Only pairs that were in contact at the last evaluation can have just separated,
  // so only they are visited: O(contacts), not O(list pairs), per step.
  pair_mark_.resize(nl_.pair_count(), 0);
  for (std::size_t k = 0; k < nc; ++k) pair_mark_[contact_p_[k]] |= 2;
  for (std::uint32_t p : prev_contacts_)
    if (!(pair_mark_[p] & 2)) h_[3 * p] = h_[3 * p + 1] = h_[3 * p + 2] = 0.0;
  for (std::uint32_t p : prev_contacts_) pair_mark_[p] = 0;
  prev_contacts_.assign(contact_p_.begin(), contact_p_.begin() + static_cast<std::ptrdiff_t>(nc));
  for (std::uint32_t p : prev_contacts_) pair_mark_[p] = 1;
}

namespace {
/// Minimum image of a difference d (m) in a periodic direction of length L with inv_L = 1/L:
/// rounding instead of comparisons keeps the pair loop free of data-dependent branches, and
/// gives the same bits as d -/+ L.
inline double wrap_rn(double d, double L, double inv_L) { return d - L * std::nearbyint(d * inv_L); }

/// First pass of the force loop: appends (i, list slot) of each overlapping list pair to ci, cp
/// and returns their number. The test runs over the flat pair arrays (pair_i, nb) so that it
/// vectorises (gathers) into a byte per pair; the append is a second, branch-free scalar pass.
/// The periodic directions are template flags so that the loop body has no branch at all.
template <bool PX, bool PY, bool PZ>
std::size_t find_contacts(std::size_t np, const std::uint32_t* __restrict pair_i, const std::uint32_t* __restrict nb,
                          const double* __restrict x, const double* __restrict y, const double* __restrict z,
                          const double* __restrict rad, const std::array<double, 3>& len, std::uint8_t* __restrict flag,
                          std::uint32_t* __restrict ci, std::uint32_t* __restrict cp) {
  const double Lx = len[0], Ly = len[1], Lz = len[2];
  const double iLx = 1.0 / Lx, iLy = 1.0 / Ly, iLz = 1.0 / Lz;
  for (std::size_t p = 0; p < np; ++p) {
    const std::uint32_t i = pair_i[p], j = nb[p];
    double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
    if constexpr (PX) dx = wrap_rn(dx, Lx, iLx);
    if constexpr (PY) dy = wrap_rn(dy, Ly, iLy);
    if constexpr (PZ) dz = wrap_rn(dz, Lz, iLz);
    const double rsum = rad[i] + rad[j];
    flag[p] = dx * dx + dy * dy + dz * dz < rsum * rsum;
  }
  std::size_t nc = 0;
  for (std::size_t p = 0; p < np; ++p) {
    ci[nc] = pair_i[p];
    cp[nc] = static_cast<std::uint32_t>(p);
    nc += flag[p];
  }
  return nc;
}

using FindContactsFn = std::size_t (*)(std::size_t, const std::uint32_t*, const std::uint32_t*, const double*,
                                       const double*, const double*, const double*, const std::array<double, 3>&,
                                       std::uint8_t*, std::uint32_t*, std::uint32_t*);
// Indexed by periodic x | y << 1 | z << 2.
constexpr FindContactsFn kFindContacts[8] = {
    find_contacts<false, false, false>, find_contacts<true, false, false>, find_contacts<false, true, false>,
    find_contacts<true, true, false>,   find_contacts<false, false, true>, find_contacts<true, false, true>,
    find_contacts<false, true, true>,   find_contacts<true, true, true>};
}  // namespace

template <class Rolling>
void DemSystem::compute_forces_impl(const Rolling& rolling) {
  const std::size_t n = s_.size();
  std::fill(s_.fx.begin(), s_.fx.end(), 0.0);
  std::fill(s_.fy.begin(), s_.fy.end(), 0.0);
  std::fill(s_.fz.begin(), s_.fz.end(), 0.0);
  std::fill(s_.tx.begin(), s_.tx.end(), 0.0);
  std::fill(s_.ty.begin(), s_.ty.end(), 0.0);
  std::fill(s_.tz.begin(), s_.tz.end(), 0.0);
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
  const bool uniform = uniform_mass_kg_ > 0.0;
  const double gn_pair = cm.gamma_n(0.5 * uniform_mass_kg_), gn_wall = cm.gamma_n(uniform_mass_kg_);

  // Pass 1: which list pairs overlap. In a suspension most list pairs (8 in 9 on the LIGGGHTS
  // bench) are apart, so this is a short branch-free loop that only appends the pair to the
  // contact list; the contact work below then runs without mispredicted branches.
  const std::uint32_t* __restrict nb = nl_.neighbors.data();
  const std::size_t np = nl_.pair_count();
  contact_i_.resize(np);
  contact_p_.resize(np);
  std::uint32_t* __restrict ci = contact_i_.data();
  std::uint32_t* __restrict cp = contact_p_.data();
  const int periodic_bits = (px ? 1 : 0) | (py ? 2 : 0) | (pz ? 4 : 0);
  pair_flag_.resize(np);
  const std::size_t nc =
      kFindContacts[periodic_bits](np, pair_i_.data(), nb, x, y, z, rad, cfg_.box.len, pair_flag_.data(), ci, cp);
  forget_separated_pairs(nc);
  contacts = static_cast<std::int64_t>(nc);

  // Pass 2a: each contact's force and torques, written per contact. Contacts touch distinct
  // list slots (their histories do not alias) and nothing is accumulated per particle here, so
  // the loop has no dependence between iterations and vectorises over contacts (gathers).
  contact_out_.resize(9 * np);
  double* __restrict oFx = contact_out_.data();
  double* __restrict oFy = oFx + np;
  double* __restrict oFz = oFy + np;
  double* __restrict oTix = oFz + np;
  double* __restrict oTiy = oTix + np;
  double* __restrict oTiz = oTiy + np;
  double* __restrict oTjx = oTiz + np;
  double* __restrict oTjy = oTjx + np;
  double* __restrict oTjz = oTjy + np;
  double* __restrict hist = h_.data();
  const double iLx = 1.0 / Lx, iLy = 1.0 / Ly, iLz = 1.0 / Lz;
  // The period of each direction, 0 where it is not periodic (wrap_rn then leaves d as it is):
  // a select on the loop-invariant flag would keep the loop from vectorising.
  const double Pxl = px ? Lx : 0.0, Pyl = py ? Ly : 0.0, Pzl = pz ? Lz : 0.0;
  const double damping_factor = cm.damping_factor;
  // Equal masses (the usual case) and mixed ones are separate loops: a select between them would
  // turn the mass loads into masked gathers, which do not vectorise.
  auto contact_loop = [&](auto uniform_masses) {
#pragma GCC ivdep
    for (std::size_t k = 0; k < nc; ++k) {
      const std::uint32_t i = ci[k], p = cp[k], j = nb[p];
      const double ri = rad[i], rj = rad[j], mi = mass[i], mj = mass[j];
      double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      dx = wrap_rn(dx, Pxl, iLx);
      dy = wrap_rn(dy, Pyl, iLy);
      dz = wrap_rn(dz, Pzl, iLz);
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
      if constexpr (!decltype(uniform_masses)::value) gn = damping_factor * std::sqrt(mi * mj / (mi + mj) * kn);
      double ftx, fty, ftz;
      const double fn = spring_dashpot(cm, dt, nx, ny, nz, rsum - r, vrx, vry, vrz, gn, hist[3 * p], hist[3 * p + 1],
                                       hist[3 * p + 2], ftx, fty, ftz);
      oFx[k] = fn * nx + ftx;
      oFy[k] = fn * ny + fty;
      oFz[k] = fn * nz + ftz;
      // Torque -R n x F_t on both spheres (the arm of j is +R_j n, its force -F_t).
      const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
      double rtx = 0.0, rty = 0.0, rtz = 0.0;
      if constexpr (Rolling::enabled) {
        // Rolling resistance q per unit radius (T_i = -R_i q, T_j = +R_j q), |q| <= mu_r |F_n|
        // (Eq. 11). q is the value that, with this contact's friction torque, stops the relative
        // rolling within the coming step; capped, it is Eq. 11's constant torque along the
        // rolling direction. Below the cap the contact holds like static friction instead of
        // flipping sign every step (chatter) or creeping at O(g dt).
        const double orx = spx[i] - spx[j], ory = spy[i] - spy[j], orz = spz[i] - spz[j];
        const double on = orx * nx + ory * ny + orz * nz;
        const double ai = ri / inertia[i], aj = rj / inertia[j], ik = 1.0 / (ai + aj);
        const double qx = ((orx - on * nx) * inv_dt + (aj - ai) * mx) * ik;
        const double qy = ((ory - on * ny) * inv_dt + (aj - ai) * my) * ik;
        const double qz = ((orz - on * nz) * inv_dt + (aj - ai) * mz) * ik;
        cap_rolling(qx, qy, qz, rolling.mu_r * std::abs(fn), rtx, rty, rtz);
      }
      oTix[k] = -ri * mx - ri * rtx;
      oTiy[k] = -ri * my - ri * rty;
      oTiz[k] = -ri * mz - ri * rtz;
      oTjx[k] = -rj * mx + rj * rtx;
      oTjy[k] = -rj * my + rj * rty;
      oTjz[k] = -rj * mz + rj * rtz;
    }
  };
  if (uniform) contact_loop(std::true_type{});
  else contact_loop(std::false_type{});
  // Pass 2b: add them to the particles, in contact order.
  for (std::size_t k = 0; k < nc; ++k) {
    const std::uint32_t i = ci[k], j = nb[cp[k]];
    fx[i] += oFx[k];
    fy[i] += oFy[k];
    fz[i] += oFz[k];
    fx[j] -= oFx[k];
    fy[j] -= oFy[k];
    fz[j] -= oFz[k];
    tx[i] += oTix[k];
    ty[i] += oTiy[k];
    tz[i] += oTiz[k];
    tx[j] += oTjx[k];
    ty[j] += oTjy[k];
    tz[j] += oTjz[k];
  }

  // Walls: a sphere of infinite mass at rest; history per particle and wall. As for pairs: find
  // the particles that touch the wall, reset the springs of those that have left it, then a
  // vectorisable loop over the touching ones (each particle once per wall: no conflicts).
  wall_contact_.resize(n);
  prev_wall_contacts_.resize(cfg_.walls.size());
  std::uint32_t* __restrict wc = wall_contact_.data();
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const PlaneWall& W = cfg_.walls[w];
    const double nx = W.nx, ny = W.ny, nz = W.nz, wpx = W.px, wpy = W.py, wpz = W.pz;
    double* __restrict whx = whx_[w].data();
    double* __restrict why = why_[w].data();
    double* __restrict whz = whz_[w].data();
    std::size_t nw = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dist = (x[i] - wpx) * nx + (y[i] - wpy) * ny + (z[i] - wpz) * nz;
      wc[nw] = static_cast<std::uint32_t>(i);
      nw += dist < rad[i];
    }
    for (std::uint32_t i : prev_wall_contacts_[w]) {
      const double dist = (x[i] - wpx) * nx + (y[i] - wpy) * ny + (z[i] - wpz) * nz;
      if (dist >= rad[i]) whx[i] = why[i] = whz[i] = 0.0;
    }
    prev_wall_contacts_[w].assign(wc, wc + nw);
    contacts += static_cast<std::int64_t>(nw);
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
        const double fn = spring_dashpot(cm, dt, nx, ny, nz, ri - dist, vrx, vry, vrz, gn, whx[i], why[i], whz[i], ftx,
                                         fty, ftz);
        fx[i] += fn * nx + ftx;
        fy[i] += fn * ny + fty;
        fz[i] += fn * nz + ftz;
        const double mx = ny * ftz - nz * fty, my = nz * ftx - nx * ftz, mz = nx * fty - ny * ftx;
        double rtx = 0.0, rty = 0.0, rtz = 0.0;
        if constexpr (Rolling::enabled) {
          // As for pairs, with the wall's infinite inertia (a_j = 0).
          const double on = spx[i] * nx + spy[i] * ny + spz[i] * nz;
          const double ia = inertia[i] / ri;
          const double qx = (spx[i] - on * nx) * inv_dt * ia - mx;
          const double qy = (spy[i] - on * ny) * inv_dt * ia - my;
          const double qz = (spz[i] - on * nz) * inv_dt * ia - mz;
          cap_rolling(qx, qy, qz, rolling.mu_r * std::abs(fn), rtx, rty, rtz);
        }
        tx[i] += -ri * (mx + rtx);
        ty[i] += -ri * (my + rty);
        tz[i] += -ri * (mz + rtz);
      }
    };
    if (uniform) wall_loop(std::true_type{});
    else wall_loop(std::false_type{});
  }
  contacts_ = contacts;
}

void DemSystem::compute_forces() {
  auto t0 = Clock::now();
  if (cfg_.rolling_model == "none" || cfg_.rolling_friction == 0.0) compute_forces_impl(RollingNone{});
  else compute_forces_impl(RollingConstantDirectional{cfg_.rolling_friction});
  seconds_force += since(t0);
}

namespace {
/// The half kick (see DemSystem::kick), all components in one pass so that m, m_add and beta are
/// read once and (M + h beta) is inverted once per particle; restrict-qualified parameters let
/// GCC vectorise it. Predict: also write 2 v_new - v_old to p; Track: accumulate the drag
/// impulse in J; Wet: read the fluid arrays (F_ext, u_f, m_add), which a dry kick leaves out.
template <bool Predict, bool Track, bool Wet>
void kick_loop(std::size_t n, double h, double gx, double gy, double gz, const double* __restrict m,
                   const double* __restrict ma, const double* __restrict b, const double* __restrict fx,
                   const double* __restrict fy, const double* __restrict fz, const double* __restrict ex,
                   const double* __restrict ey, const double* __restrict ez, const double* __restrict ux,
                   const double* __restrict uy, const double* __restrict uz, double* __restrict vx, double* __restrict vy,
                   double* __restrict vz, double* __restrict Jx, double* __restrict Jy, double* __restrict Jz,
                   double* __restrict px, double* __restrict py, double* __restrict pz) {
  for (std::size_t i = 0; i < n; ++i) {
    // Dry (!Wet): F_ext, u_f and m_add are zero and not read (DemConfig::dry).
    const double M = Wet ? m[i] + ma[i] : m[i], bi = b[i], inv_D = 1.0 / (M + h * bi);
    const double v0x = vx[i], v0y = vy[i], v0z = vz[i];
    double ax = fx[i], ay = fy[i], az = fz[i];
    if constexpr (Wet) {
      ax += ex[i];
      ay += ey[i];
      az += ez[i];
    }
    ax += m[i] * gx;
    ay += m[i] * gy;
    az += m[i] * gz;
    if constexpr (Wet) {
      ax += bi * ux[i];
      ay += bi * uy[i];
      az += bi * uz[i];
    }
    const double v1x = (M * v0x + h * ax) * inv_D;
    const double v1y = (M * v0y + h * ay) * inv_D;
    const double v1z = (M * v0z + h * az) * inv_D;
    vx[i] = v1x;
    vy[i] = v1y;
    vz[i] = v1z;
    if constexpr (Track) {
      Jx[i] += h * bi * (ux[i] - v1x);
      Jy[i] += h * bi * (uy[i] - v1y);
      Jz[i] += h * bi * (uz[i] - v1z);
    }
    if constexpr (Predict) {
      px[i] = 2.0 * v1x - v0x;
      py[i] = 2.0 * v1y - v0y;
      pz[i] = 2.0 * v1z - v0z;
    }
  }
}

/// Spin half kick, w += h T / I, with the prediction as above.
template <bool Predict>
void kick_spin(std::size_t n, double h, const double* __restrict I, const double* __restrict tx,
               const double* __restrict ty, const double* __restrict tz, double* __restrict wx, double* __restrict wy,
               double* __restrict wz, double* __restrict px, double* __restrict py, double* __restrict pz) {
  for (std::size_t i = 0; i < n; ++i) {
    const double h_I = h / I[i];
    const double w0x = wx[i], w0y = wy[i], w0z = wz[i];
    const double w1x = w0x + h_I * tx[i], w1y = w0y + h_I * ty[i], w1z = w0z + h_I * tz[i];
    wx[i] = w1x;
    wy[i] = w1y;
    wz[i] = w1z;
    if constexpr (Predict) {
      px[i] = 2.0 * w1x - w0x;
      py[i] = 2.0 * w1y - w0y;
      pz[i] = 2.0 * w1z - w0z;
    }
  }
}

template <bool Predict, bool Track, bool Wet>
void kick_all(std::size_t n, double h, const std::array<double, 3>& g, ParticleStore& s, std::vector<double>* pred) {
  double* p[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  if constexpr (Predict)
    for (int c = 0; c < 6; ++c) p[c] = pred[c].data();
  kick_loop<Predict, Track, Wet>(n, h, g[0], g[1], g[2], s.mass.data(), s.madd.data(), s.beta.data(), s.fx.data(),
                                s.fy.data(), s.fz.data(), s.ext_x.data(), s.ext_y.data(), s.ext_z.data(), s.ufx.data(),
                                s.ufy.data(), s.ufz.data(), s.vx.data(), s.vy.data(), s.vz.data(), s.drag_jx.data(),
                                s.drag_jy.data(), s.drag_jz.data(), p[0], p[1], p[2]);
  kick_spin<Predict>(n, h, s.inertia.data(), s.tx.data(), s.ty.data(), s.tz.data(), s.wx.data(), s.wy.data(),
                     s.wz.data(), p[3], p[4], p[5]);
}
}  // namespace


void DemSystem::kick(double h, bool predict) {
  // Half kick of velocity Verlet with the drag implicit (backward Euler over the half step):
  //   (M + h beta) v_new = M v + h (F + F_ext + m g + beta u_f),  M = m + m_add.
  // beta -> infinity gives v = u_f + F/beta: stable for any particle response time.
  // With `predict` (the step's first kick) it also writes the velocities the coming forces see
  // (see predict_velocities), 2 v(n+1/2) - v(n), while v(n) is at hand: one pass over the
  // arrays instead of a copy of v(n), the kick and a prediction pass (~8 % of a DEM step).
  const std::size_t n = s_.n_local;
  if (predict)
    for (int c = 0; c < 6; ++c) pred_[c].resize(s_.size());
  const bool track = cfg_.track_drag_impulse;
  // Dry only without drag tracking (tracking is for the coupling, which has fluid).
  const bool wet = !cfg_.dry || track;
  auto& g = cfg_.gravity_m_s2;
  if (predict && track) kick_all<true, true, true>(n, h, g, s_, pred_);
  else if (track) kick_all<false, true, true>(n, h, g, s_, pred_);
  else if (predict && wet) kick_all<true, false, true>(n, h, g, s_, pred_);
  else if (wet) kick_all<false, false, true>(n, h, g, s_, pred_);
  else if (predict) kick_all<true, false, false>(n, h, g, s_, pred_);
  else kick_all<false, false, false>(n, h, g, s_, pred_);
  if (predict) {
    // Ghost copies are not integrated here: they see the velocities their owner sent.
    const std::vector<double>* cur[6] = {&s_.vx, &s_.vy, &s_.vz, &s_.wx, &s_.wy, &s_.wz};
    for (int c = 0; c < 6; ++c)
      for (std::size_t i = n; i < s_.size(); ++i) pred_[c][i] = (*cur[c])[i];
  }
}

void DemSystem::drift() {
  const std::size_t n = s_.n_local;
  const double dt = cfg_.dt_s;
  for (int c = 0; c < 3; ++c) {
    double* __restrict x = (c == 0 ? s_.x : c == 1 ? s_.y : s_.z).data();
    const double* __restrict v = (c == 0 ? s_.vx : c == 1 ? s_.vy : s_.vz).data();
    for (std::size_t i = 0; i < n; ++i) x[i] += dt * v[i];
  }
}

void DemSystem::predict_velocities() {
  // Velocity Verlet evaluates forces at x(n+1) but only knows v(n+1/2); a dashpot fed with that
  // half-step-old velocity under-damps by O(gamma dt / m) (restitution 4 % low for e = 0.1 at
  // 100 steps per contact). The forces therefore see v(n+1) predicted to second order,
  // v(n+1/2) + (dt/2) a(n) = 2 v(n+1/2) - v(n), written by the step's first kick; at t = 0
  // (here) they see v(0).
  const std::vector<double>* cur[6] = {&s_.vx, &s_.vy, &s_.vz, &s_.wx, &s_.wy, &s_.wz};
  for (int c = 0; c < 6; ++c) pred_[c] = *cur[c];
}

void DemSystem::step() {
  if (!initialized_) initialize();
  auto t0 = Clock::now();
  kick(0.5 * cfg_.dt_s, true);
  drift();
  seconds_integrate += since(t0);
  if (needs_rebuild()) rebuild();
  compute_forces();
  t0 = Clock::now();
  kick(0.5 * cfg_.dt_s, false);
  seconds_integrate += since(t0);
  time_ += cfg_.dt_s;
  ++steps_;
}

double DemSystem::kinetic_energy_j() const {
  double e = 0.0;
  for (std::size_t i = 0; i < s_.n_local; ++i) {
    e += 0.5 * s_.mass[i] * (s_.vx[i] * s_.vx[i] + s_.vy[i] * s_.vy[i] + s_.vz[i] * s_.vz[i]);
    e += 0.5 * s_.inertia[i] * (s_.wx[i] * s_.wx[i] + s_.wy[i] * s_.wy[i] + s_.wz[i] * s_.wz[i]);
  }
  return e;
}

double DemSystem::pair_overlap(std::size_t i, std::size_t j) const {
  const double dx = min_image(s_.x[i] - s_.x[j], cfg_.box.len[0], cfg_.box.periodic[0]);
  const double dy = min_image(s_.y[i] - s_.y[j], cfg_.box.len[1], cfg_.box.periodic[1]);
  const double dz = min_image(s_.z[i] - s_.z[j], cfg_.box.len[2], cfg_.box.periodic[2]);
  return s_.radius[i] + s_.radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
}

double DemSystem::spring_energy_j() const {
  const double kn = cfg_.contact.kn_n_m, kt = cfg_.contact.kt_n_m;
  double e = 0.0;
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      const double ov = pair_overlap(i, nl_.neighbors[p]);
      if (ov > 0.0) e += 0.5 * kn * ov * ov + 0.5 * kt * (h_[3 * p] * h_[3 * p] + h_[3 * p + 1] * h_[3 * p + 1] + h_[3 * p + 2] * h_[3 * p + 2]);
    }
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const PlaneWall& W = cfg_.walls[w];
    for (std::size_t i = 0; i < s_.size(); ++i) {
      const double ov = s_.radius[i] - ((s_.x[i] - W.px) * W.nx + (s_.y[i] - W.py) * W.ny + (s_.z[i] - W.pz) * W.nz);
      if (ov > 0.0)
        e += 0.5 * kn * ov * ov +
             0.5 * kt * (whx_[w][i] * whx_[w][i] + why_[w][i] * why_[w][i] + whz_[w][i] * whz_[w][i]);
    }
  }
  return e;
}

DemState DemSystem::export_state() const {
  DemState st;
  st.store = s_;
  st.ref_x = ref_x_;
  st.ref_y = ref_y_;
  st.ref_z = ref_z_;
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      if (h_[3 * p] == 0.0 && h_[3 * p + 1] == 0.0 && h_[3 * p + 2] == 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[nl_.neighbors[p]];
      const double sg = a < b ? 1.0 : -1.0;
      st.pair_id_a.push_back(std::min(a, b));
      st.pair_id_b.push_back(std::max(a, b));
      st.pair_hx.push_back(sg * h_[3 * p]);
      st.pair_hy.push_back(sg * h_[3 * p + 1]);
      st.pair_hz.push_back(sg * h_[3 * p + 2]);
    }
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w)
    for (std::size_t i = 0; i < s_.size(); ++i)
      st.wall_h.insert(st.wall_h.end(), {whx_[w][i], why_[w][i], whz_[w][i]});
  st.steps = steps_;
  st.time_s = time_;
  return st;
}

void DemSystem::import_state(const DemState& st) {
  s_ = st.store;
  const std::size_t n = s_.size();
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    whx_[w].resize(n);
    why_[w].resize(n);
    whz_[w].resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      whx_[w][i] = st.wall_h[3 * (w * n + i)];
      why_[w][i] = st.wall_h[3 * (w * n + i) + 1];
      whz_[w][i] = st.wall_h[3 * (w * n + i) + 2];
    }
  }
  double rmax = 0.0;
  for (double r : s_.radius) rmax = std::max(rmax, r);
  cutoff_m_ = 2.0 * rmax + cfg_.skin_m;
  update_uniform_mass();
  // Build the list at the stored reference positions, so that the next rebuild happens at the
  // same step as in the uninterrupted run, then restore the histories onto it.
  ParticleStore at_ref = s_;
  at_ref.x = st.ref_x;
  at_ref.y = st.ref_y;
  at_ref.z = st.ref_z;
  nl_.build(at_ref, cfg_.box, cutoff_m_);
  ref_x_ = st.ref_x;
  ref_y_ = st.ref_y;
  ref_z_ = st.ref_z;
  std::vector<double> h(3 * st.pair_id_a.size());
  for (std::size_t q = 0; q < st.pair_id_a.size(); ++q) {
    h[3 * q] = st.pair_hx[q];
    h[3 * q + 1] = st.pair_hy[q];
    h[3 * q + 2] = st.pair_hz[q];
  }
  restore_histories(st.pair_id_a, st.pair_id_b, h);
  rescan_wall_contacts();
  steps_ = st.steps;
  time_ = st.time_s;
  initialized_ = true;
}

}  // namespace boycott::particles
