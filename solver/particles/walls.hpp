#pragma once
// Plane walls: a point on the plane and the unit normal pointing into the domain. Scenes list
// the walls they need (y = 0 and y = W for the channel; other directions later).
#include <vector>

namespace boycott::particles {

struct PlaneWall {
  double px = 0.0, py = 0.0, pz = 0.0;  ///< a point of the plane, m
  double nx = 0.0, ny = 1.0, nz = 0.0;  ///< unit normal into the domain
};

}  // namespace boycott::particles
