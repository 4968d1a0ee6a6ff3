#pragma once
// Small builders shared by the particle tests.
#include "particles/dem_system.hpp"

namespace boycott::particles::testing {

inline constexpr double kD = 0.6e-3;    // m, Table III diameter
inline constexpr double kR = 0.3e-3;    // m
inline constexpr double kRho = 2650.0;  // kg/m^3
inline constexpr double kKn = 3.5;      // N/m

/// A cube of side L, periodic in x, z (and y unless `walls`), no gravity, Table III contact.
inline DemConfig make_config(double L, bool walls, double e, double mu, double mu_r, double dt,
                             bool clip = false) {
  DemConfig c;
  c.box.lo = {0.0, 0.0, 0.0};
  c.box.len = {L, L, L};
  c.box.periodic = {true, !walls, true};
  if (walls) {
    c.walls.push_back(PlaneWall{0.0, 0.0, 0.0, 0.0, 1.0, 0.0});
    c.walls.push_back(PlaneWall{0.0, L, 0.0, 0.0, -1.0, 0.0});
  }
  c.dt_s = dt;
  c.skin_m = 0.3e-3;
  c.contact = LinearSpringDashpot(kKn, e, 0.5, mu, clip);
  c.rolling_model = mu_r > 0.0 ? "constant_directional" : "none";
  c.rolling_friction = mu_r;
  return c;
}

inline double particle_mass() {
  return kRho * 4.0 / 3.0 * kPi * kR * kR * kR;
}

}  // namespace boycott::particles::testing
