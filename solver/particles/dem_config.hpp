#pragma once
// The particle engine's configuration as a case sets it, and the models the case switches on.
#include <array>
#include <string>
#include <vector>

#include "core/case_params.hpp"
#include "particles/contact_models.hpp"
#include "particles/neighbor_list.hpp"
#include "particles/walls.hpp"

namespace boycott {
class ModelTimers;
}

namespace boycott::particles {

struct DemConfig {
  BoxGeometry box;
  std::vector<PlaneWall> walls;
  std::array<double, 3> gravity_m_s2 = {0.0, 0.0, 0.0};
  double dt_s = 2.0e-5;
  double skin_m = 0.3e-3;
  /// Several ranks: how far (m) a particle may move along z past its slab before the next
  /// rebuild moves it to its new rank. The pairs need no limit (the list's bound covers the
  /// pairs across slab faces); this one keeps the particles with the rank of their slab, half
  /// the skin by default (from_case), and a coupled run sets the reach of the fluid window.
  double slab_excursion_m = 0.15e-3;
  LinearSpringDashpot contact;
  std::string rolling_model = "constant_directional";  ///< or "none"
  double rolling_friction = 0.1;
  /// Accumulate the applied drag impulse per particle (ParticleStore::drag_j*), for coupling.
  bool track_drag_impulse = false;
  /// No fluid (the dem_only scene): the external forces, fluid velocities and added masses are
  /// all zero, so the kicks need not read them (a DEM step is memory-bound: 21 streams instead
  /// of 36). Only the implicit drag beta toward rest remains. initialize() checks the zeros.
  bool dry = false;
  /// The contact search tests only the list pairs that were within skin / 3 of touching when
  /// last filtered (DemSystem's near pairs); off, it tests the whole list every step. The
  /// contacts and every result are the same bits either way: a switch for tests and benchmarks.
  bool near_pairs = true;

  /// Channel of the case: periodic x and z, walls at y = 0 and y = W unless periodic_y.
  static DemConfig from_case(const CaseParams& p);
};

/// Registers the engine's models of case p in a run's timers: the contact model (naming the
/// normal-force clip when contact.clip_attractive_normal is on), rolling friction where it acts,
/// and the neighbour search. The scene adds "integration", whose detail says what its kicks hold.
void activate_dem_models(ModelTimers& t, const CaseParams& p);

}  // namespace boycott::particles
