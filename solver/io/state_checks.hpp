#pragma once
// Checks of a run's state as read back from a checkpoint, before anything is resumed from it: a
// file can be intact (its hash matches) and still hold a state no run can continue from (written
// by a faulty build, or edited). Each failure is a CheckpointError naming the file, the dataset
// and the check.
#include <array>
#include <string>
#include <vector>

#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::io {

/// The box a run's particles live in.
struct StateBounds {
  std::array<double, 3> length_m{};  ///< x, y, z extents
  std::array<bool, 3> periodic{};    ///< periodic coordinates may lie up to one length outside
};

/// Particle ids non-negative and unique; every particle array finite; centres inside the box
/// (periodic coordinates within one box length of it, between wraps; walled ones within one
/// radius of the walls); contact-history ids non-negative. `file` and `prefix` ("dem.") name it.
void check_state(const particles::DemState& s, const StateBounds& b, const std::string& file,
                 const std::string& prefix);
/// Every field finite; the fluid fraction (its three time levels) in (0, 1].
void check_state(const fluid::FluidState& s, const std::string& file, const std::string& prefix);
/// Every value finite (the coupling's arrays, scene sums).
void check_finite(const std::vector<std::vector<double>>& arrays, const std::string& file,
                  const std::string& prefix);

}  // namespace boycott::io
