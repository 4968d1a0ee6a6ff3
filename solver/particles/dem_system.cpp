// The DEM engine's set-up and neighbour-list upkeep: start-up, when and how the list is rebuilt
// (wrapping, spatial reordering, histories carried over), and the energies. The configuration
// from a case is in dem_config.cpp, the step in integrator.cpp, the forces in contact_forces.cpp.
#include "particles/dem_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/constants.hpp"
#include "core/timers.hpp"
#include "particles/displacement_bound.hpp"
#include "particles/min_image.hpp"

namespace boycott::particles {

DemSystem::DemSystem(const DemConfig& cfg)
    : cfg_(cfg), dd_(SlabDecomposition::serial(cfg.box.lo[2], cfg.box.lo[2] + cfg.box.len[2])) {
  walls_.set_wall_count(cfg_.walls.size());
  // A third of the skin: over the campaign's flows the fewest pair tests per step, renewals
  // included (bench/substep_reach.py, docs/performance.md).
  near_.margin_m = cfg_.near_pairs ? cfg_.skin_m / 3.0 : 0.0;
}

void DemSystem::initialize() {
  if (cfg_.dry)
    for (std::size_t i = 0; i < s_.size(); ++i)
      if (s_.ext_x[i] != 0.0 || s_.ext_y[i] != 0.0 || s_.ext_z[i] != 0.0 || s_.ufx[i] != 0.0 ||
          s_.ufy[i] != 0.0 || s_.ufz[i] != 0.0 || s_.madd[i] != 0.0)
        throw std::logic_error(
            "DemConfig::dry is set but a particle has a fluid force, velocity or added mass");
  if (dd_.parallel()) {
    // The ghosts carry their owner's velocities at the force time, so those come first.
    set_cutoff_and_uniform_properties();
    predict_velocities();
    rebuild_parallel(!carry_.ready);
    carry_.ready = false;
    compute_forces();
    initialized_ = true;
    return;
  }
  set_cutoff_and_uniform_properties();
  rebuild();
  predict_velocities();
  compute_forces();
  initialized_ = true;
}

void DemSystem::set_cutoff_and_uniform_properties() {
  // On several ranks over the local particles only (the ghosts may still be copies from before
  // the change), their extremes reduced over the ranks; one rank keeps no ghosts.
  const std::size_t n = dd_.parallel() ? s_.n_local : s_.size();
  const double inf = std::numeric_limits<double>::infinity();
  double rmin = inf, rmax = 0.0, mmin = inf, mmax = -inf, imin = inf, imax = -inf;
  for (std::size_t i = 0; i < n; ++i) {
    rmin = std::min(rmin, s_.radius[i]);
    rmax = std::max(rmax, s_.radius[i]);
    mmin = std::min(mmin, s_.mass[i]);
    mmax = std::max(mmax, s_.mass[i]);
    imin = std::min(imin, s_.inertia[i]);
    imax = std::max(imax, s_.inertia[i]);
  }
  if (dd_.parallel()) {
    rmin = global_min(dd_.comm, rmin);
    rmax = global_max(dd_.comm, rmax);
    mmin = global_min(dd_.comm, mmin);
    mmax = global_max(dd_.comm, mmax);
    imin = global_min(dd_.comm, imin);
    imax = global_max(dd_.comm, imax);
  }
  verlet_.cutoff_m = 2.0 * rmax + cfg_.skin_m;
  uniform_.mass_kg = std::isfinite(mmin) && mmin == mmax ? mmin : 0.0;
  const bool same_r = std::isfinite(rmin) && rmin == rmax && imin == imax;
  uniform_.radius_m = same_r ? rmin : 0.0;
  uniform_.inertia_kg_m2 = same_r ? imin : 0.0;
}

void DemSystem::set_particle_properties(double r, double rho) {
  const double m = rho * 4.0 / 3.0 * kPi * r * r * r, inertia = 0.4 * m * r * r;
  int changed = 0;
  for (std::size_t i = 0; i < s_.n_local; ++i)
    if (s_.radius[i] != r || s_.mass[i] != m) {
      s_.radius[i] = r, s_.mass[i] = m, s_.inertia[i] = inertia;
      changed = 1;
    }
  if (dd_.parallel()) {
    MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_MAX, dd_.comm);
    if (!changed) return;
    set_cutoff_and_uniform_properties();
    rebuild_parallel();
    return;
  }
  if (!changed) return;
  set_cutoff_and_uniform_properties();
  rebuild();
}

void DemSystem::force_rebuild() {
  // Only the list: the forces of the current positions stay valid, and evaluating them again
  // would advance the shear springs twice in one step.
  rebuild();
}

DisplacementSpread DemSystem::local_displacement_box() const {
  if (fused_.drift_box_fresh) return fused_.drift_box;
  return displacement_box(s_.n_local, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                          verlet_.ref_y.data(), verlet_.ref_z.data());
}

bool DemSystem::needs_rebuild() const {
  // Exact while every particle is within skin/2 of a common centre (displacement_bound.hpp).
  // Walls are not in the list: every particle is tested against every wall each step.
  const std::size_t n = s_.size();
  if (n == 0) return false;
  // (one rank holds no ghost copies: n is the local count)
  DisplacementSpread sp =
      n == s_.n_local ? local_displacement_box()
                      : displacement_box(n, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                                         verlet_.ref_y.data(), verlet_.ref_z.data());
  if (box_within_half_skin(sp, cfg_.skin_m)) return false;
  sp.sum = displacement_sums(n, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                             verlet_.ref_y.data(), verlet_.ref_z.data());
  const auto c = displacement_centres(sp, static_cast<double>(n));
  const auto w = largest_offsets2(n, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                                  verlet_.ref_y.data(), verlet_.ref_z.data(), c[0], c[1]);
  return std::min(w[0], w[1]) > 0.25 * cfg_.skin_m * cfg_.skin_m;
}

void DemSystem::wrap_periodic() {
  for (int d = 0; d < 3; ++d) {
    if (!cfg_.box.periodic[d]) continue;
    auto& c = d == 0 ? s_.x : (d == 1 ? s_.y : s_.z);
    const double lo = cfg_.box.lo[d], len = cfg_.box.len[d];
    for (double& v : c) v -= len * std::floor((v - lo) / len);
  }
}

void DemSystem::sort_by_cell() {
  const auto order = verlet_.list.bin_and_order(s_, cfg_.box, verlet_.cutoff_m);
  s_.permute(order);
  std::vector<double> tmp(order.size());
  for (auto& a : pred_) {
    if (a.size() != order.size()) continue;
    for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
    a.swap(tmp);
  }
  walls_.permute(order, tmp);
}

void DemSystem::rebuild() {
  auto t0 = std::chrono::steady_clock::now();
  collect_histories();
  // Wrap periodic coordinates into the box, then store particles cell by cell.
  wrap_periodic();
  sort_by_cell();
  verlet_.list.build_binned(s_, cfg_.box, verlet_.cutoff_m);
  finish_rebuild(t0);
}

void DemSystem::finish_rebuild(std::chrono::steady_clock::time_point t0) {
  restore_histories(carry_.springs.a, carry_.springs.b, carry_.springs.h);
  near_.fresh = false;  // a new list
  walls_.rescan();
  verlet_.set_reference(s_);
  ++counters_.rebuilds;
  seconds_neighbor += seconds_since(t0);
}

std::int64_t DemSystem::global_count() const {
  return dd_.parallel() ? global_sum(dd_.comm, static_cast<std::int64_t>(s_.n_local))
                        : static_cast<std::int64_t>(s_.n_local);
}

double DemSystem::kinetic_energy_j() const {
  double e = 0.0;
  for (std::size_t i = 0; i < s_.n_local; ++i) {
    e += 0.5 * s_.mass[i] * (s_.vx[i] * s_.vx[i] + s_.vy[i] * s_.vy[i] + s_.vz[i] * s_.vz[i]);
    e += 0.5 * s_.inertia[i] * (s_.wx[i] * s_.wx[i] + s_.wy[i] * s_.wy[i] + s_.wz[i] * s_.wz[i]);
  }
  return dd_.parallel() ? ordered_sum(dd_.comm, e) : e;
}

double DemSystem::pair_overlap(std::size_t i, std::size_t j) const {
  const double dx = min_image(s_.x[i] - s_.x[j], cfg_.box.period(0), cfg_.box.inv_len(0));
  const double dy = min_image(s_.y[i] - s_.y[j], cfg_.box.period(1), cfg_.box.inv_len(1));
  const double dz = min_image(s_.z[i] - s_.z[j], cfg_.box.period(2), cfg_.box.inv_len(2));
  return s_.radius[i] + s_.radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
}

double DemSystem::spring_energy_j() const {
  const double kn = cfg_.contact.kn_n_m, kt = cfg_.contact.kt_n_m;
  double e = 0.0;
  std::size_t q = 0;
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = verlet_.list.offsets[i]; p < verlet_.list.offsets[i + 1]; ++p) {
      const double ov = pair_overlap(i, verlet_.list.neighbors[p]);
      const double* h = pairs_.springs.of_slot(p, q);
      if (ov > 0.0)
        e += 0.5 * kn * ov * ov + (h ? 0.5 * kt * (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]) : 0.0);
    }
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const PlaneWall& W = cfg_.walls[w];
    for (std::size_t i = 0; i < s_.n_local; ++i) {
      const double ov =
          s_.radius[i] - ((s_.x[i] - W.px) * W.nx + (s_.y[i] - W.py) * W.ny + (s_.z[i] - W.pz) * W.nz);
      if (ov > 0.0)
        e += 0.5 * kn * ov * ov + 0.5 * kt *
                                      (walls_.hx[w][i] * walls_.hx[w][i] + walls_.hy[w][i] * walls_.hy[w][i] +
                                       walls_.hz[w][i] * walls_.hz[w][i]);
    }
  }
  return e;
}

}  // namespace boycott::particles
