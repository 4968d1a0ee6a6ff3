// The DEM on several MPI ranks (SlabDecomposition): each rank integrates the particles of its
// z-slab and holds copies ("ghosts") of the other ranks' particles within the neighbour cutoff of
// its slab, stored after its own. A pair across a slab face is computed on both ranks, each
// keeping the force on its own particle; the arithmetic of a pair is exactly antisymmetric (the
// same bits seen from either side), so both ranks carry the same shear history for it. At each
// neighbour-list rebuild the particles that left the slab move to their new rank with
// everything that belongs to them (coupling arrays, predicted velocities, wall and pair
// histories, keyed by global ids); between rebuilds only the ghosts' positions and velocities
// are refreshed. One rank never comes here.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/timers.hpp"
#include "particles/dem_system.hpp"
#include "particles/displacement_bound.hpp"

namespace boycott::particles {

namespace {

/// Sends buffer out[r] to rank r and returns what arrives, sources in rank order; counts[r]: the
/// number of values that came from rank r.
std::vector<double> exchange(MPI_Comm comm, const std::vector<std::vector<double>>& out,
                             std::vector<int>& counts) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<int> sc(size), sd(size), rd(size);
  counts.assign(size, 0);
  std::size_t total_out = 0;
  for (int r = 0; r < size; ++r) {
    sc[r] = static_cast<int>(out[r].size());
    sd[r] = static_cast<int>(total_out);
    total_out += out[r].size();
  }
  MPI_Alltoall(sc.data(), 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::size_t total_in = 0;
  for (int r = 0; r < size; ++r) {
    rd[r] = static_cast<int>(total_in);
    total_in += static_cast<std::size_t>(counts[r]);
  }
  std::vector<double> send;
  send.reserve(total_out);
  for (const auto& b : out) send.insert(send.end(), b.begin(), b.end());
  std::vector<double> recv(total_in);
  MPI_Alltoallv(send.data(), sc.data(), sd.data(), MPI_DOUBLE, recv.data(), counts.data(), rd.data(),
                MPI_DOUBLE, comm);
  return recv;
}

/// Ghost data on creation: id, x, y, z, radius, mass, inertia, 6 predicted velocities, spin.
constexpr int kGhostNew = 16;
/// Ghost refresh between rebuilds: x, y, z, 6 predicted velocities, spin.
constexpr int kGhostUpdate = 12;

}  // namespace

void DemSystem::decompose(const SlabDecomposition& d) {
  if (dd_.parallel()) throw std::logic_error("DemSystem::decompose called twice");
  dd_ = d;
  ghost_send_.assign(static_cast<std::size_t>(dd_.size), {});
  if (!dd_.parallel()) return;
  // A run that stepped on its own first (a bed poured before the flow starts) keeps its contact
  // histories; the next initialize() builds the parallel list.
  if (initialized_) {
    collect_histories();
    carry_.ready = true;
    initialized_ = false;
  }
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < s_.size(); ++i)
    if (dd_.owner(s_.z[i]) == dd_.rank) keep.push_back(i);
  select_particles(keep);
}

void DemSystem::select_particles(const std::vector<std::size_t>& keep) {
  s_.keep_increasing(keep);
  s_.n_local = keep.size();
  for (auto& a : pred_) compact_increasing(a, keep);
  walls_.keep_increasing(keep);
}

bool DemSystem::needs_rebuild_parallel() {
  // The pairs: as on one rank, every particle within skin/2 of a centre common to all ranks
  // (displacement_bound.hpp). A ghost held here is a particle that was within the cutoff of this
  // slab along z at the build, so a pair of a local particle and one that is not held was at
  // least the cutoff apart then, and is covered by the same bound. The slabs: a local particle
  // may leave its slab by at most cfg_.slab_excursion_m along z before it moves rank.
  const std::size_t n = s_.n_local;
  const DisplacementSpread sp = local_displacement_box();
  // One reduction for the bounding box (exact in any order); where the box does not settle it,
  // one ordered sum for the mean (the same bits on every rank, so that every rank takes the same
  // decision).
  double ext[6] = {sp.hi[0], sp.hi[1], sp.hi[2], -sp.lo[0], -sp.lo[1], -sp.lo[2]};
  const auto tw = std::chrono::steady_clock::now();
  MPI_Allreduce(MPI_IN_PLACE, ext, 6, MPI_DOUBLE, MPI_MAX, dd_.comm);
  seconds_wait += seconds_since(tw);
  DisplacementSpread all;
  for (int c = 0; c < 3; ++c) all.hi[c] = ext[c], all.lo[c] = -ext[3 + c];
  if (std::max(all.hi[2], -all.lo[2]) > cfg_.slab_excursion_m) return true;
  if (box_within_half_skin(all, cfg_.skin_m)) return false;
  const auto local = displacement_sums(n, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                                       verlet_.ref_y.data(), verlet_.ref_z.data());
  const std::vector<double> sums =
      ordered_sum(dd_.comm, std::vector<double>{local[0], local[1], local[2], static_cast<double>(n)});
  for (int c = 0; c < 3; ++c) all.sum[c] = sums[c];
  const auto c = displacement_centres(all, sums[3]);
  auto w = largest_offsets2(n, s_.x.data(), s_.y.data(), s_.z.data(), verlet_.ref_x.data(),
                            verlet_.ref_y.data(), verlet_.ref_z.data(), c[0], c[1]);
  MPI_Allreduce(MPI_IN_PLACE, w.data(), 2, MPI_DOUBLE, MPI_MAX, dd_.comm);
  return std::min(w[0], w[1]) > 0.25 * cfg_.skin_m * cfg_.skin_m;
}

void DemSystem::drop_ghosts() {
  s_.resize(s_.n_local);
  for (auto& a : pred_)
    if (a.size() > s_.n_local) a.resize(s_.n_local);
}

void DemSystem::rebuild_parallel(bool collect) {
  const auto t0 = std::chrono::steady_clock::now();
  if (collect) collect_histories();
  drop_ghosts();
  wrap_periodic();
  migrate();
  sort_by_cell();
  exchange_ghosts();
  verlet_.list.build(s_, cfg_.box, verlet_.cutoff_m, s_.n_local);
  finish_rebuild(t0);
}

void DemSystem::migrate() {
  const std::size_t n = s_.n_local, nw = cfg_.walls.size();
  const auto size = static_cast<std::size_t>(dd_.size);
  std::vector<int> dest(n);
  std::vector<std::pair<std::int64_t, int>> leaving;  // (id, destination), sorted by id below
  for (std::size_t i = 0; i < n; ++i) {
    dest[i] = dd_.owner(s_.z[i]);
    if (dest[i] != dd_.rank) leaving.emplace_back(s_.id[i], dest[i]);
  }
  std::vector<std::vector<double>> out(size), out_pairs(size);
  std::vector<std::size_t> keep;
  keep.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (dest[i] == dd_.rank) {
      keep.push_back(i);
      continue;
    }
    auto& b = out[static_cast<std::size_t>(dest[i])];
    b.push_back(static_cast<double>(s_.id[i]));
    s_.for_each_array([&](std::vector<double>& a) { b.push_back(a[i]); });
    for (const auto& a : pred_) b.push_back(a[i]);
    for (std::size_t w = 0; w < nw; ++w)
      b.insert(b.end(), {walls_.hx[w][i], walls_.hy[w][i], walls_.hz[w][i]});
  }
  // The shear springs of the leaving particles go with them (both partners' new ranks).
  std::sort(leaving.begin(), leaving.end());
  auto dest_of = [&](std::int64_t id) {
    auto it = std::lower_bound(leaving.begin(), leaving.end(), std::pair<std::int64_t, int>{id, -1});
    return it != leaving.end() && it->first == id ? it->second : -1;
  };
  for (std::size_t q = 0; q < carry_.springs.a.size(); ++q) {
    const int da = dest_of(carry_.springs.a[q]), db = dest_of(carry_.springs.b[q]);
    const auto send_to = [&](int r) {
      out_pairs[static_cast<std::size_t>(r)].insert(
          out_pairs[static_cast<std::size_t>(r)].end(),
          {static_cast<double>(carry_.springs.a[q]), static_cast<double>(carry_.springs.b[q]),
           carry_.springs.h[3 * q], carry_.springs.h[3 * q + 1], carry_.springs.h[3 * q + 2]});
    };
    if (da >= 0) send_to(da);
    if (db >= 0 && db != da) send_to(db);
  }
  std::vector<int> counts;
  const std::vector<double> in = exchange(dd_.comm, out, counts);
  const std::vector<double> in_pairs = exchange(dd_.comm, out_pairs, counts);

  // Keep the staying particles in their order, then append the arrivals in source-rank order.
  select_particles(keep);
  const std::size_t record = 1 + ParticleStore::kArrays + 6 + 3 * nw;
  for (std::size_t at = 0; at + record <= in.size(); at += record) {
    std::size_t k = at;
    s_.id.push_back(static_cast<std::int64_t>(in[k++]));
    s_.for_each_array([&](std::vector<double>& a) { a.push_back(in[k++]); });
    for (auto& a : pred_) a.push_back(in[k++]);
    for (std::size_t w = 0; w < nw; ++w) {
      walls_.hx[w].push_back(in[k++]);
      walls_.hy[w].push_back(in[k++]);
      walls_.hz[w].push_back(in[k++]);
    }
    ++counters_.migrations;
  }
  s_.n_local = s_.id.size();
  for (std::size_t at = 0; at + 5 <= in_pairs.size(); at += 5) {
    carry_.springs.a.push_back(static_cast<std::int64_t>(in_pairs[at]));
    carry_.springs.b.push_back(static_cast<std::int64_t>(in_pairs[at + 1]));
    carry_.springs.h.insert(carry_.springs.h.end(), {in_pairs[at + 2], in_pairs[at + 3], in_pairs[at + 4]});
  }
}

void DemSystem::exchange_ghosts() {
  const std::size_t n = s_.n_local;
  const auto size = static_cast<std::size_t>(dd_.size);
  ghost_send_.assign(size, {});
  std::vector<std::vector<double>> out(size);
  for (std::size_t r = 0; r < size; ++r) {
    if (static_cast<int>(r) == dd_.rank) continue;
    auto& list = ghost_send_[r];
    auto& b = out[r];
    for (std::size_t i = 0; i < n; ++i) {
      if (!(dd_.distance_to_slab(s_.z[i], static_cast<int>(r)) < verlet_.cutoff_m)) continue;
      list.push_back(static_cast<std::uint32_t>(i));
      b.insert(b.end(), {static_cast<double>(s_.id[i]), s_.x[i], s_.y[i], s_.z[i], s_.radius[i], s_.mass[i],
                         s_.inertia[i], pred_[0][i], pred_[1][i], pred_[2][i], pred_[3][i], pred_[4][i],
                         pred_[5][i], s_.wx[i], s_.wy[i], s_.wz[i]});
    }
  }
  std::vector<int> counts;
  const std::vector<double> in = exchange(dd_.comm, out, counts);
  const std::size_t ng = in.size() / kGhostNew, total = n + ng;
  s_.id.resize(total);
  s_.for_each_array([&](std::vector<double>& a) { a.resize(total, 0.0); });
  for (auto& a : pred_) a.resize(total, 0.0);
  for (std::size_t g = 0; g < ng; ++g) {
    const double* v = in.data() + g * kGhostNew;
    const std::size_t i = n + g;
    s_.id[i] = static_cast<std::int64_t>(v[0]);
    s_.x[i] = v[1], s_.y[i] = v[2], s_.z[i] = v[3];
    s_.radius[i] = v[4], s_.mass[i] = v[5], s_.inertia[i] = v[6];
    for (int c = 0; c < 6; ++c) pred_[c][i] = v[7 + c];
    s_.wx[i] = v[13], s_.wy[i] = v[14], s_.wz[i] = v[15];
  }
}

void DemSystem::forward_ghosts() {
  const auto size = static_cast<std::size_t>(dd_.size);
  std::vector<std::vector<double>> out(size);
  for (std::size_t r = 0; r < size; ++r) {
    auto& b = out[r];
    b.reserve(kGhostUpdate * ghost_send_[r].size());
    for (std::uint32_t i : ghost_send_[r])
      b.insert(b.end(), {s_.x[i], s_.y[i], s_.z[i], pred_[0][i], pred_[1][i], pred_[2][i], pred_[3][i],
                         pred_[4][i], pred_[5][i], s_.wx[i], s_.wy[i], s_.wz[i]});
  }
  std::vector<int> counts;
  const std::vector<double> in = exchange(dd_.comm, out, counts);
  const std::size_t n = s_.n_local, ng = in.size() / kGhostUpdate;
  if (n + ng != s_.size()) throw std::logic_error("DemSystem: ghost refresh does not match the ghosts held");
  for (std::size_t g = 0; g < ng; ++g) {
    const double* v = in.data() + g * kGhostUpdate;
    const std::size_t i = n + g;
    s_.x[i] = v[0], s_.y[i] = v[1], s_.z[i] = v[2];
    for (int c = 0; c < 6; ++c) pred_[c][i] = v[3 + c];
    s_.wx[i] = v[9], s_.wy[i] = v[10], s_.wz[i] = v[11];
  }
}

}  // namespace boycott::particles
