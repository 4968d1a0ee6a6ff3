#include "fluid/fluid_settings.hpp"

#include "core/case_params.hpp"

namespace boycott::fluid {

FluidSettings FluidSettings::from_case(const CaseParams& p) {
  FluidSettings s;
  s.grid = GridSpec::from_case(p);
  s.density_kg_m3 = p.fluid.density_kg_m3;
  s.viscosity_pa_s = p.fluid.viscosity_pa_s;
  s.vreman = p.fluid.subgrid_model == "vreman";
  s.top_slip = p.domain.top_wall == "slip";
  s.body_acceleration_m_s2 = p.flow.body_acceleration_m_s2;
  s.target_mean_flux_z_m_s = p.flow.target_mean_velocity_z_m_s;
  s.simple_max_iterations = static_cast<int>(p.numerics.simple_max_iterations);
  s.simple_tolerance = p.numerics.simple_tolerance;
  s.velocity_relaxation = p.numerics.velocity_relaxation;
  s.cfl_max = p.numerics.cfl_max;
  s.dt_max_s = p.time.dt_cfd_s;
  s.piso = p.numerics.pressure_velocity_coupling == "piso";
  s.piso_correctors = static_cast<int>(p.numerics.piso_correctors);
  s.simple_correctors = static_cast<int>(p.numerics.simple_correctors);
  return s;
}

}  // namespace boycott::fluid
