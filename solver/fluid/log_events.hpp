#pragma once
// PETSc log events of the fluid step, so that `-log_view` shows where a step's time goes beside
// the KSP events (registered once per process, after PetscInitialize).
#include <petscsys.h>

namespace boycott::fluid {

struct FluidEvents {
  PetscLogEvent subgrid, fluxes, momentum_assembly, momentum_sweep, pressure_assembly, continuity, correction;
};
const FluidEvents& fluid_events();

/// Logs the lifetime of a scope as one event.
class LogScope {
 public:
  explicit LogScope(PetscLogEvent e) : e_(e) { PetscLogEventBegin(e_, 0, 0, 0, 0); }
  ~LogScope() { PetscLogEventEnd(e_, 0, 0, 0, 0); }
  LogScope(const LogScope&) = delete;
  LogScope& operator=(const LogScope&) = delete;

 private:
  PetscLogEvent e_;
};

}  // namespace boycott::fluid
