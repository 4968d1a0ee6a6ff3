#pragma once
// The fluid solver's settings: grid, fluid properties, numerics and forcing, built from a case.
#include <array>
#include <limits>
#include <string>

#include "core/grid_spec.hpp"

namespace boycott {
struct CaseParams;
}

namespace boycott::fluid {

struct FluidSettings {
  GridSpec grid;
  double density_kg_m3 = 1000.0;
  double viscosity_pa_s = 1.0e-3;  ///< dynamic
  bool vreman = false;             ///< Vreman subgrid viscosity on/off
  double vreman_constant = 0.07;
  bool top_slip = false;  ///< y = W is a slip (mirror) wall instead of no-slip
  std::array<double, 3> body_acceleration_m_s2 = {0.0, 0.0, 0.0};
  /// Flux controller target for the volume mean of alpha_f w (m/s); NaN = controller off.
  double target_mean_flux_z_m_s = std::numeric_limits<double>::quiet_NaN();
  int simple_max_iterations = 30;
  double simple_tolerance = 1.0e-6;
  double velocity_relaxation = 1.0;  ///< see CaseParams::Numerics
  double cfl_max = 0.5;
  double dt_max_s = 1.0e-3;
  bool quick = true;  ///< false: first-order upwind convection (for comparisons)
  /// PISO instead of SIMPLE (numerics.pressure_velocity_coupling): one momentum solve and
  /// piso_correctors pressure corrections per step, no convergence test.
  bool piso = false;
  int piso_correctors = 2;
  /// Pressure corrections per SIMPLE iteration (numerics.simple_correctors).
  int simple_correctors = 2;
  /// Builds the settings of a case: grid, fluid, numerics, `[flow]` forcing.
  static FluidSettings from_case(const CaseParams& p);
  /// Pressure-velocity coupling in words ("SIMPLEC", "SIMPLEC, 2 correctors" or "PISO, 2 correctors").
  std::string coupling_name() const {
    if (piso) return "PISO, " + std::to_string(piso_correctors) + " correctors";
    const std::string name = "SIMPLEC";
    return simple_correctors > 1 ? name + ", " + std::to_string(simple_correctors) + " correctors" : name;
  }
};

}  // namespace boycott::fluid
