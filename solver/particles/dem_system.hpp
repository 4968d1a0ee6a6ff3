#pragma once
// The DEM engine: particles, walls, neighbour list with Verlet skin, contact histories and the
// velocity-Verlet integrator with the coupling hook (implicit linear drag, added mass).
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/case_params.hpp"
#include "particles/dem_config.hpp"
#include "particles/dem_parts.hpp"
#include "particles/displacement_bound.hpp"
#include "particles/neighbor_list.hpp"
#include "particles/pair_histories.hpp"
#include "particles/particle_store.hpp"
#include "particles/slab_decomposition.hpp"
#include "particles/walls.hpp"
#include "stats/running.hpp"

namespace boycott::particles {

/// Everything the next step depends on, for checkpoints: all particles of the run, whatever
/// the number of ranks that wrote it.
struct DemState {
  ParticleStore store;
  std::vector<double> ref_x, ref_y, ref_z;         ///< positions at the last neighbour-list build
  std::vector<std::int64_t> pair_id_a, pair_id_b;  ///< contact histories, id_a < id_b
  std::vector<double> pair_hx, pair_hy, pair_hz;   ///< shear displacement seen from id_a, m
  std::vector<double> wall_h;  ///< per wall, per particle (storage order), 3 components, m
  std::int64_t steps = 0;
  double time_s = 0.0;
  /// Written on several ranks: each particle's rank (the particles of a rank are stored together,
  /// in that rank's storage order), so that the same number of ranks resumes bit for bit.
  int n_ranks = 1;
  std::vector<std::int64_t> owner_rank;
};

class DemSystem {
 public:
  explicit DemSystem(const DemConfig& cfg);

  ParticleStore& particles() { return s_; }
  const ParticleStore& particles() const { return s_; }
  const DemConfig& config() const { return cfg_; }

  /// Gives every particle (of all ranks) this radius (m) and density (kg/m^3), where they differ
  /// from what they have, and rebuilds the neighbour list for them (a run branched from another
  /// with smaller or lighter particles). Collective.
  void set_particle_properties(double radius_m, double density_kg_m3);
  /// After writing radius, mass or inertia into particles() directly (a packing that grows the
  /// particles step by step): the contact loops stop taking one radius, mass and moment of
  /// inertia for all particles (the dashpots' damping is chosen from the pair's masses) until the
  /// next initialize() or import_state() finds them equal again.
  void particle_sizes_changed() {
    uniform_ = UniformProperties{};
    near_.fresh = false;
  }
  /// Whether the contact loops take one radius and moment of inertia for all particles.
  bool equal_radii() const { return uniform_.radius_m > 0.0; }
  /// Adds a particle (before `initialize`, or followed by `force_rebuild`).
  void add_particle(std::int64_t gid, double x, double y, double z, double radius_m, double density_kg_m3);
  /// Random non-overlapping insertion of `count` spheres with centres in [lo, hi] (m), at least
  /// `gap_m` apart from each other and `radius` from every wall. Throws when the region is too
  /// full to place them within a bounded number of attempts.
  void insert_random(std::int64_t count, double radius_m, double density_kg_m3, std::array<double, 3> lo,
                     std::array<double, 3> hi, std::uint64_t seed, double gap_m = 0.0);

  /// Shares the particles among the ranks of `d`: each rank keeps those whose centre lies in its
  /// slab. Every rank must hold the same particles when it is called (after insertion; when the
  /// system already stepped on every rank alike, initialize() again after it). From then on the particles of
  /// the other ranks within the neighbour cutoff of this rank's slab are held as ghost copies after the local
  /// ones, and particles that leave the slab move to their new rank at each neighbour-list rebuild, with
  /// their histories.
  void decompose(const SlabDecomposition& d);
  const SlabDecomposition& decomposition() const { return dd_; }

  /// Builds the neighbour list and the forces at t = 0. Call once after insertion.
  void initialize();
  /// One velocity-Verlet step of dt.
  void step();
  /// `count` velocity-Verlet steps of dt, as many calls of step() would make them (bit for bit),
  /// with the closing half kick of each step, the opening one of the next and its drift fused
  /// into one pass over the particle arrays. With `vz_sums` (count values), vz_sums[k] is the
  /// sum of the local particles' v_z (m/s) at the end of step k, added in storage order: the
  /// same bits as summing particles().vz after the k-th of as many step() calls.
  void advance(int count, double* vz_sums = nullptr);
  /// advance(count), asking `stop` after every `check_every` steps but the last (the same bits:
  /// the fused passes run on across the asks); returns the steps made: `count`, or fewer when
  /// `stop` said yes (the particles are then part-way through, for a caller that discards them).
  /// `stop` must give every rank the same answer.
  int advance_interruptible(int count, int check_every, const std::function<bool()>& stop);
  /// Rebuilds the neighbour list now (re-sorts and wraps; forces and histories are kept).
  void force_rebuild();

  double time_s() const { return counters_.time_s; }
  std::int64_t steps() const { return counters_.steps; }
  std::int64_t rebuilds() const { return counters_.rebuilds; }
  /// How often the contact search's near pairs were filtered from the list (0 when they are off).
  std::int64_t near_pair_renewals() const { return near_.renewals; }
  /// The near pairs the contact search tests now (0 when they are off).
  std::size_t near_pair_count() const { return near_.slot.size(); }
  /// Pairs in overlap at the last force evaluation (particle-particle and particle-wall).
  std::int64_t contact_count() const { return counters_.contacts; }
  const NeighborList& neighbor_list() const { return verlet_.list; }

  /// Of all particles on all ranks (collective), J.
  double kinetic_energy_j() const;
  /// Elastic energy stored in the normal and tangential springs of this rank's contacts.
  double spring_energy_j() const;
  /// Particles on all ranks (collective).
  std::int64_t global_count() const;
  /// Particles that changed rank, on this rank (arrivals), since the start.
  std::int64_t migrations() const { return counters_.migrations; }

  /// All particles (collective): on several ranks gathered to rank 0 (the other ranks get the
  /// step and time only).
  DemState export_state() const;
  /// Collective; every rank passes the whole state. Written on as many ranks as this run has,
  /// each rank takes its own particles in their stored order (the run continues bit for bit);
  /// otherwise each takes those in its slab.
  void import_state(const DemState& st);

  /// Seconds spent in neighbour search (migration and ghost set-up included), force
  /// evaluation, integration, and the ghost updates of the steps between rebuilds.
  double seconds_neighbor = 0.0, seconds_force = 0.0, seconds_integrate = 0.0, seconds_ghosts = 0.0;
  /// Several ranks: seconds in the rebuild test's reduction, the first point of every DEM step
  /// where the ranks meet, so mostly the wait for the rank with the most work (the reduction of
  /// a few doubles itself takes microseconds).
  double seconds_wait = 0.0;

  /// When set (output.force_budget_y), every force evaluation adds the y-force (N) of each wall
  /// contact times dt_s into this histogram at the particle's y: the walls' share of the budget.
  stats::Histogram* wall_force_y_budget = nullptr;

 private:
  // The force evaluation (contact_forces.cpp): pairs, then walls.
  template <class Rolling>
  void compute_forces_impl(const Rolling& rolling);
  /// Zeroes the forces and torques that a fused kick has not already zeroed.
  void zero_unspent_forces();
  // The contact search (contact_search.cpp).
  /// The overlapping list pairs into pairs_ (row, slot), their springs carried over; their number.
  std::size_t find_pair_contacts();
  /// Whether no pair outside near_ can touch yet.
  bool near_pairs_exact() const;
  /// near_ from the list's np pairs, pairs_.flag holding which are within the margin.
  void renew_near_pairs(std::size_t np);
  template <class Rolling>
  void add_pair_forces(const Rolling& rolling, std::size_t nc);
  /// Returns the number of wall contacts.
  template <class Rolling>
  std::size_t add_wall_forces(const Rolling& rolling);
  // Several ranks (parallel_dem.cpp): the rebuild moves particles between ranks and renews the
  // ghost copies; between rebuilds the ghosts' positions and velocities are refreshed.
  bool needs_rebuild_parallel();
  /// collect: take the contact histories from the current list (false: from carry_, set by
  /// the caller).
  void rebuild_parallel(bool collect = true);
  void import_parallel(const DemState& st);
  DemState export_local() const;
  void migrate();
  void exchange_ghosts();
  void forward_ghosts();
  void drop_ghosts();
  /// Keeps the particles keep[0] < keep[1] < ... (local ones), with their predicted velocities
  /// and wall histories, in that order.
  void select_particles(const std::vector<std::size_t>& keep);
  /// The list cutoff (2 r_max + skin) and uniform_ from the particles (collective on several
  /// ranks).
  void set_cutoff_and_uniform_properties();
  void compute_forces();
  void kick(double h, bool predict);
  void drift();
  /// The closing half kick h of a step, the next step's opening one with its prediction, and its
  /// drift: kick(h, false); kick(h, true); drift() in one pass. With `vz_sum`, also the sum of
  /// v_z after the closing kick (see advance).
  void kick_kick_drift(double h, double* vz_sum = nullptr);
  void copy_ghost_predictions();
  /// advance and advance_interruptible: `count` steps, asking `stop` (when given) after every
  /// `check_every` of them but the last; returns the steps made.
  int advance_steps(int count, double* vz_sums, int check_every, const std::function<bool()>* stop);
  /// After the drift: the list rebuilt or the ghosts refreshed, then the forces.
  void advance_to_forces();
  bool needs_rebuild() const;
  /// The displacement box of the local particles: the fused kick's when fresh, else a pass.
  DisplacementSpread local_displacement_box() const;
  void rebuild();
  /// The end of every rebuild, once the new list stands: the carried springs put back into it,
  /// the wall contacts rescanned, the reference positions taken; counted and timed from t0.
  void finish_rebuild(std::chrono::steady_clock::time_point t0);
  /// Periodic coordinates wrapped into the box (before a rebuild bins them).
  void wrap_periodic();
  /// The particles (and their predictions and wall histories) stored cell by cell.
  void sort_by_cell();
  void collect_histories();
  /// r_i + r_j - |x_i - x_j| (minimum image), m; positive when the pair overlaps.
  double pair_overlap(std::size_t i, std::size_t j) const;
  void predict_velocities();
  void restore_histories(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                         const std::vector<double>& h);
  /// The fast way (false when it cannot be used) and the general one; the same result.
  bool restore_histories_by_row(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                                const std::vector<double>& h);
  void restore_histories_by_key(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                                const std::vector<double>& h);
  /// List slot p (row i, partner j) takes the carried history hq (3 values, seen from the lower
  /// id); slots must come in increasing order.
  void restore_history(std::uint32_t p, std::size_t i, std::uint32_t j, const double* hq);

  DemConfig cfg_;
  SlabDecomposition dd_;
  ParticleStore s_;
  // Several ranks: for each destination rank, the local particles it holds as ghosts, in the
  // order it stores them.
  std::vector<std::vector<std::uint32_t>> ghost_send_;
  std::vector<double> pred_[6];  ///< v, w (m/s, rad/s) seen by the forces: predicted to the force time
  VerletState verlet_;
  UniformProperties uniform_;
  PairContacts pairs_;
  NearPairs near_;
  WallContacts walls_;
  HistoryCarry carry_;
  FusedPass fused_;
  DemCounters counters_;
  bool initialized_ = false;
};

}  // namespace boycott::particles
