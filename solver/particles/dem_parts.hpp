#pragma once
// The state DemSystem keeps beside its particles, one struct per concern: the neighbour list and
// its rebuild test, the contacts of a force evaluation (pairs and walls), the springs carried
// through a rebuild, what a fused kick pass leaves behind, and the run's counters.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "particles/displacement_bound.hpp"
#include "particles/neighbor_list.hpp"
#include "particles/pair_histories.hpp"
#include "particles/particle_store.hpp"

namespace boycott::particles {

/// The Verlet list and what the rebuild test compares against.
struct VerletState {
  NeighborList list;
  double cutoff_m = 0.0;                    ///< 2 r_max + skin
  std::vector<double> ref_x, ref_y, ref_z;  ///< positions at the last build, m
  /// Particle i of each list slot (the list's rows, flattened; rebuilt with the list).
  std::vector<std::uint32_t> row_of_slot;
  void set_reference(const ParticleStore& s) {
    ref_x = s.x;
    ref_y = s.y;
    ref_z = s.z;
  }
};

/// A thinner list inside the Verlet list, for the contact search (contact_search.cpp): the list
/// pairs whose surfaces were less than margin_m apart at its last renewal, in list order, as
/// particle (row), partner and list slot. Exact while every particle (ghost copies included) is
/// within margin_m / 2 of a common displacement since then; renewed from the list when not, and
/// after every rebuild or change of radii (fresh = false).
struct NearPairs {
  double margin_m = 0.0;  ///< 0: off (the search tests the whole list)
  bool fresh = false;
  std::vector<std::uint32_t> row, partner, slot;
  std::vector<double> ref_x, ref_y, ref_z;  ///< positions at the renewal, m
  std::int64_t renewals = 0;
};

/// The radius (m) and moment of inertia (kg m^2) every particle has (the usual monodisperse
/// case), else 0: the contact loops then take both as constants instead of gathering them. The
/// mass (kg) likewise, on its own.
struct UniformProperties {
  double mass_kg = 0.0, radius_m = 0.0, inertia_kg_m2 = 0.0;
};

/// The pairs in overlap at this evaluation (particle i and list slot p of each, found by the
/// first pass of the force loop, in increasing slot order) and their tangential springs, per
/// contact: the force loop reads them in order, and nothing streams the 8 in 9 list pairs that
/// are apart.
struct PairContacts {
  std::vector<std::uint32_t> row, slot;
  PairHistories springs;
  std::vector<std::uint8_t> flag;  ///< the overlap test's result per list slot (scratch)
  /// Per contact of the current block of contacts (contact_forces.cpp): force on i (N), torques
  /// on i and on j (N m), 9 arrays of the block size (scratch).
  std::vector<double> block_out;
};

/// The particles' tangential springs at each wall (m, per wall, per particle in storage order)
/// and which particles touch each wall.
struct WallContacts {
  std::vector<std::vector<double>> hx, hy, hz;
  /// Particles touching each wall at the last evaluation.
  std::vector<std::vector<std::uint32_t>> touching;
  /// Scratch of one evaluation: the contacts with one wall, and the overlap test per particle.
  std::vector<std::uint32_t> found;
  std::vector<std::uint8_t> flag;

  void set_wall_count(std::size_t walls) {
    hx.resize(walls);
    hy.resize(walls);
    hz.resize(walls);
  }
  std::size_t wall_count() const { return hx.size(); }
  /// A new particle, touching no wall.
  void append_particle() {
    for (std::size_t w = 0; w < wall_count(); ++w) {
      hx[w].push_back(0.0);
      hy[w].push_back(0.0);
      hz[w].push_back(0.0);
    }
  }
  /// Reorders the springs as ParticleStore::permute does (tmp: scratch of the order's size).
  void permute(const std::vector<std::size_t>& order, std::vector<double>& tmp) {
    for (auto* wh : {&hx, &hy, &hz})
      for (auto& a : *wh) {
        for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = a[order[k]];
        a.swap(tmp);
      }
  }
  /// Keeps the springs of particles keep[0] < keep[1] < ..., as ParticleStore::keep_increasing.
  void keep_increasing(const std::vector<std::size_t>& keep) {
    for (auto* wh : {&hx, &hy, &hz})
      for (auto& a : *wh) compact_increasing(a, keep);
  }
  /// After a reordering the remembered contacts are stale: every particle with a spring is one
  /// (the spring is zero for all others).
  void rescan() {
    touching.assign(wall_count(), {});
    for (std::size_t w = 0; w < wall_count(); ++w)
      for (std::size_t i = 0; i < hx[w].size(); ++i)
        if (hx[w][i] != 0.0 || hy[w][i] != 0.0 || hz[w][i] != 0.0)
          touching[w].push_back(static_cast<std::uint32_t>(i));
  }
};

/// The pair springs through the next rebuild (or from a checkpoint), keyed by global ids, and
/// the scratch of putting them back into a new list by rows (contact_history.cpp).
struct HistoryCarry {
  CarriedHistories springs;
  bool ready = false;  ///< several ranks: `springs` holds the histories for the next rebuild
  // Storage slot of each id, and the carried entries per list row (partner slot, entry index).
  std::vector<std::uint32_t> slot_of_id, row_start, row_fill, row_partner, row_entry;
};

/// What a fused kick-kick-drift pass (integrator.cpp) leaves for the rest of its step.
struct FusedPass {
  std::vector<double> vz_end;  ///< v_z (m/s) after the pass's closing kick (advance's sums)
  /// The local particles' forces and torques are zero (the pass spent them); the next
  /// compute_forces zeroes only the ghost copies'.
  bool local_forces_zeroed = false;
  /// The displacement box of the local particles as the pass drifted them, for the rebuild test
  /// that follows it (fresh until that test has read it).
  DisplacementSpread drift_box;
  bool drift_box_fresh = false;
};

/// The run's clock and event counts.
struct DemCounters {
  double time_s = 0.0;
  std::int64_t steps = 0, rebuilds = 0;
  std::int64_t contacts = 0;    ///< pairs in overlap at the last force evaluation, walls included
  std::int64_t migrations = 0;  ///< particles that arrived from another rank since the start
};

}  // namespace boycott::particles
