#pragma once
// A turbulent start for wall-bounded flows driven in +z (the sediment_transport scene).
//
// Started from rest, a channel flow at Re ~ 10^4 on a grid of a millimetre stays a laminar Stokes
// layer for the whole run: its diffusion time H^2/nu is ~1000 s, and nothing on the grid seeds an
// instability within seconds. Its wall stress then falls as t^-1/2 instead of reaching the
// turbulent value. This start is the rough-wall log law over a floor (a bed top) plus
// large-scale random perturbations, from which the flow is turbulent within ~0.5 s (measured in
// tests/verification/fluid/test_turbulent_start.cpp).
#include <cstdint>

namespace boycott::fluid {

class FluidSolver;

struct TurbulentStartSettings {
  double bulk_velocity_m_s = 0.0;  ///< U, the mean of w over the box (including below the floor)
  double floor_m = 0.0;            ///< y below which the fluid starts at rest (a bed top), m
  double roughness_m = 1.0e-3;     ///< Nikuradse's equivalent sand roughness k_s, m
  double mode_amplitude = 0.05;    ///< amplitude of each perturbation mode, relative to U
  int max_wavenumber = 3;          ///< modes 0..max in x and z (not both 0)
  std::uint64_t seed = 1;          ///< random phases, the same on every rank
};

/// Sets u, v, w (current and previous levels) on a grid with a wall at y = 0 and a top at y = H:
/// w = C ln(1 + (y - floor) / z0) above the floor, z0 = k_s / 30, with C such that the box mean
/// of w is U; plus, in each component, sum over modes (a, b) of
///   A U sin(2 pi (a x / L_x + b z / L_z) + phi) sin(2 pi (a + b) y' / H' + psi),
/// y' = y - floor, H' = H - floor, times sin(pi y' / (2 H')), which vanishes at the floor. The
/// first pressure correction removes the perturbations' divergence.
void start_turbulent_channel(FluidSolver& f, const TurbulentStartSettings& s);

}  // namespace boycott::fluid
