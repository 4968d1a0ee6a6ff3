#pragma once
// Placing a case's particles, shared by the scenes that have particles.
#include "core/case_params.hpp"
#include "particles/dem_system.hpp"

namespace boycott::scenes {

/// Inserts particles.count spheres by particles.insertion: "random" uniformly in the box, "bed"
/// into the lower part of the channel (y) at a loose solid fraction of 0.3, from which gravity
/// settles them, "packed" (dense beds up to random close packing) by random insertion at reduced
/// radius followed by growth to full size with the DEM (see grow_packing).
void insert_case_particles(particles::DemSystem& dem, const CaseParams& p);

/// Grows particles inserted at radius r0 to r1 over `steps` DEM steps without gravity, with a
/// velocity damping that removes the kinetic energy the overlaps release, then relaxes. Used for
/// dense packings that random sequential insertion cannot reach (above about 0.45).
void grow_packing(particles::DemSystem& dem, double r0_m, double r1_m, double density_kg_m3, int steps);

}  // namespace boycott::scenes
