// Checkpoint state of the DEM engine: export and import of everything the next step depends
// on (particles, reference positions of the neighbour list, contact histories). On several
// ranks the state is gathered to rank 0 in rank order, and every rank picks its part on import.
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "particles/dem_system.hpp"

namespace boycott::particles {

namespace {

/// Gathers a per-rank vector to rank 0 in rank order (the other ranks get an empty one).
template <class T>
std::vector<T> gather_to_root(MPI_Comm comm, const std::vector<T>& local) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int n = static_cast<int>(local.size());
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<T> all;
  if (rank == 0) {
    int total = 0;
    for (int r = 0; r < size; ++r) displs[r] = total, total += counts[r];
    all.resize(static_cast<std::size_t>(total));
  }
  const MPI_Datatype type = sizeof(T) == 8 && std::is_integral_v<T> ? MPI_INT64_T : MPI_DOUBLE;
  MPI_Gatherv(local.data(), n, type, all.data(), counts.data(), displs.data(), type, 0, comm);
  return all;
}

}  // namespace

DemState DemSystem::export_state() const {
  if (!dd_.parallel()) return export_local();
  const DemState loc = export_local();
  DemState st;
  st.steps = counters_.steps;
  st.time_s = counters_.time_s;
  st.n_ranks = dd_.size;
  const MPI_Comm comm = dd_.comm;
  st.store.id = gather_to_root(comm, loc.store.id);
  ParticleStore local_store = loc.store;
  std::vector<std::vector<double>> arrays;
  local_store.for_each_array([&](std::vector<double>& a) { arrays.push_back(gather_to_root(comm, a)); });
  std::size_t k = 0;
  st.store.for_each_array([&](std::vector<double>& a) { a = std::move(arrays[k++]); });
  st.store.n_local = st.store.id.size();
  st.ref_x = gather_to_root(comm, loc.ref_x);
  st.ref_y = gather_to_root(comm, loc.ref_y);
  st.ref_z = gather_to_root(comm, loc.ref_z);
  st.pair_id_a = gather_to_root(comm, loc.pair_id_a);
  st.pair_id_b = gather_to_root(comm, loc.pair_id_b);
  st.pair_hx = gather_to_root(comm, loc.pair_hx);
  st.pair_hy = gather_to_root(comm, loc.pair_hy);
  st.pair_hz = gather_to_root(comm, loc.pair_hz);
  const std::size_t n = s_.n_local;
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    const std::vector<double> mine(loc.wall_h.begin() + static_cast<std::ptrdiff_t>(3 * w * n),
                                   loc.wall_h.begin() + static_cast<std::ptrdiff_t>(3 * (w + 1) * n));
    const auto all = gather_to_root(comm, mine);
    st.wall_h.insert(st.wall_h.end(), all.begin(), all.end());
  }
  const auto owners = gather_to_root(comm, std::vector<std::int64_t>(n, dd_.rank));
  st.owner_rank = owners;
  return st;
}

DemState DemSystem::export_local() const {
  DemState st;
  st.store = s_;
  st.store.resize(s_.n_local);
  st.ref_x.assign(verlet_.ref_x.begin(), verlet_.ref_x.begin() + static_cast<std::ptrdiff_t>(s_.n_local));
  st.ref_y.assign(verlet_.ref_y.begin(), verlet_.ref_y.begin() + static_cast<std::ptrdiff_t>(s_.n_local));
  st.ref_z.assign(verlet_.ref_z.begin(), verlet_.ref_z.begin() + static_cast<std::ptrdiff_t>(s_.n_local));
  // The local rows' pairs with a history, in list order (the histories are kept in it).
  for (std::size_t q = 0; q < pairs_.springs.slots().size(); ++q) {
    const std::uint32_t p = pairs_.springs.slots()[q];
    if (verlet_.row_of_slot[p] >= s_.n_local) break;
    const double* hq = pairs_.springs.of_contact(q);
    if (hq[0] == 0.0 && hq[1] == 0.0 && hq[2] == 0.0) continue;
    const std::int64_t a = s_.id[verlet_.row_of_slot[p]], b = s_.id[verlet_.list.neighbors[p]];
    const double sg = a < b ? 1.0 : -1.0;
    st.pair_id_a.push_back(std::min(a, b));
    st.pair_id_b.push_back(std::max(a, b));
    st.pair_hx.push_back(sg * hq[0]);
    st.pair_hy.push_back(sg * hq[1]);
    st.pair_hz.push_back(sg * hq[2]);
  }
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w)
    for (std::size_t i = 0; i < s_.n_local; ++i)
      st.wall_h.insert(st.wall_h.end(), {walls_.hx[w][i], walls_.hy[w][i], walls_.hz[w][i]});
  st.steps = counters_.steps;
  st.time_s = counters_.time_s;
  return st;
}

void DemSystem::import_state(const DemState& st) {
  if (dd_.parallel()) {
    import_parallel(st);
    return;
  }
  s_ = st.store;
  const std::size_t n = s_.size();
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    walls_.hx[w].resize(n);
    walls_.hy[w].resize(n);
    walls_.hz[w].resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      walls_.hx[w][i] = st.wall_h[3 * (w * n + i)];
      walls_.hy[w][i] = st.wall_h[3 * (w * n + i) + 1];
      walls_.hz[w][i] = st.wall_h[3 * (w * n + i) + 2];
    }
  }
  set_cutoff_and_uniform_properties();
  // Build the list at the stored reference positions, so that the next rebuild happens at the
  // same step as in the uninterrupted run, then restore the histories onto it.
  ParticleStore at_ref = s_;
  at_ref.x = st.ref_x;
  at_ref.y = st.ref_y;
  at_ref.z = st.ref_z;
  verlet_.list.build(at_ref, cfg_.box, verlet_.cutoff_m);
  verlet_.ref_x = st.ref_x;
  verlet_.ref_y = st.ref_y;
  verlet_.ref_z = st.ref_z;
  std::vector<double> h(3 * st.pair_id_a.size());
  for (std::size_t q = 0; q < st.pair_id_a.size(); ++q) {
    h[3 * q] = st.pair_hx[q];
    h[3 * q + 1] = st.pair_hy[q];
    h[3 * q + 2] = st.pair_hz[q];
  }
  restore_histories(st.pair_id_a, st.pair_id_b, h);
  walls_.rescan();
  counters_.steps = st.steps;
  counters_.time_s = st.time_s;
  initialized_ = true;
}

void DemSystem::import_parallel(const DemState& st) {
  const std::size_t total = st.store.id.size();
  // Same number of ranks: each rank's own particles in their stored order (bitwise); otherwise
  // by slab.
  const bool same_layout = st.n_ranks == dd_.size && st.owner_rank.size() == total;
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < total; ++i)
    if (same_layout ? st.owner_rank[i] == dd_.rank : dd_.owner(st.store.z[i]) == dd_.rank) mine.push_back(i);
  s_ = st.store;
  s_.permute(mine);
  s_.n_local = mine.size();
  s_.resize(mine.size());
  const std::size_t n = mine.size();
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w) {
    walls_.hx[w].resize(n);
    walls_.hy[w].resize(n);
    walls_.hz[w].resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t q = 3 * (w * total + mine[k]);
      walls_.hx[w][k] = st.wall_h[q];
      walls_.hy[w][k] = st.wall_h[q + 1];
      walls_.hz[w][k] = st.wall_h[q + 2];
    }
  }
  for (auto& a : pred_) a.assign(n, 0.0);  // set by the next step's first kick
  set_cutoff_and_uniform_properties();
  carry_.springs.a = st.pair_id_a;
  carry_.springs.b = st.pair_id_b;
  carry_.springs.h.resize(3 * st.pair_id_a.size());
  for (std::size_t q = 0; q < st.pair_id_a.size(); ++q) {
    carry_.springs.h[3 * q] = st.pair_hx[q];
    carry_.springs.h[3 * q + 1] = st.pair_hy[q];
    carry_.springs.h[3 * q + 2] = st.pair_hz[q];
  }
  if (same_layout) {
    // As the uninterrupted run left it: ghosts and list of its last rebuild, at the reference
    // positions, so that the next rebuild comes at the same step. The ghosts' current positions
    // and velocities arrive with the next step's refresh.
    verlet_.ref_x.resize(n), verlet_.ref_y.resize(n), verlet_.ref_z.resize(n);
    for (std::size_t k = 0; k < n; ++k)
      verlet_.ref_x[k] = st.ref_x[mine[k]], verlet_.ref_y[k] = st.ref_y[mine[k]],
      verlet_.ref_z[k] = st.ref_z[mine[k]];
    std::vector<double> now[3] = {s_.x, s_.y, s_.z};
    s_.x = verlet_.ref_x, s_.y = verlet_.ref_y, s_.z = verlet_.ref_z;
    exchange_ghosts();
    verlet_.list.build(s_, cfg_.box, verlet_.cutoff_m, s_.n_local);
    // The histories belong to the pairs that overlap now (the current positions, the ghosts'
    // included).
    std::copy(now[0].begin(), now[0].end(), s_.x.begin());
    std::copy(now[1].begin(), now[1].end(), s_.y.begin());
    std::copy(now[2].begin(), now[2].end(), s_.z.begin());
    forward_ghosts();
    restore_histories(carry_.springs.a, carry_.springs.b, carry_.springs.h);
    walls_.rescan();
  } else {
    // Another number of ranks: a fresh rebuild at the current positions (the run continues, not
    // bit for bit).
    rebuild_parallel(false);
  }
  counters_.steps = st.steps;
  counters_.time_s = st.time_s;
  initialized_ = true;
}

}  // namespace boycott::particles
