// Checkpoint state of the DEM engine: export and import of everything the next step depends
// on (particles, reference positions of the neighbour list, contact histories).
#include <algorithm>
#include <vector>

#include "particles/dem_system.hpp"

namespace boycott::particles {

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
