#include "fluid/log_events.hpp"

namespace boycott::fluid {

const FluidEvents& fluid_events() {
  static const FluidEvents e = [] {
    PetscClassId id;
    FluidEvents ev{};
    PetscClassIdRegister("boycott fluid", &id);
    PetscLogEventRegister("FluidSubgrid", id, &ev.subgrid);
    PetscLogEventRegister("FluidFaceFluxes", id, &ev.fluxes);
    PetscLogEventRegister("FluidMomentumAsm", id, &ev.momentum_assembly);
    PetscLogEventRegister("FluidMomentumSweep", id, &ev.momentum_sweep);
    PetscLogEventRegister("FluidPressureAsm", id, &ev.pressure_assembly);
    PetscLogEventRegister("FluidContinuity", id, &ev.continuity);
    PetscLogEventRegister("FluidCorrection", id, &ev.correction);
    return ev;
  }();
  return e;
}

}  // namespace boycott::fluid
