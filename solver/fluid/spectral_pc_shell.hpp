#pragma once
// The spectral preconditioner (spectral_poisson_pc.hpp) as a PETSc PCSHELL of the pressure
// solve, on one rank or on FFTW's z-slabs.
#include <petscdmda.h>
#include <petscksp.h>

#include <memory>

#include "core/grid_spec.hpp"
#include "fluid/spectral_poisson_pc.hpp"

namespace boycott::fluid {

/// The spectral preconditioner as a PETSc PCSHELL: one application costs a few ms against
/// BoomerAMG's set-up of ~150 ms per step and ~15 ms per V-cycle. (Gathering the whole vector to
/// every rank and transforming it there made an application slower on 2 ranks than on one.)
struct SpectralPcShell {
  // One rank: the serial transform on the global vector (which is in natural order). Several:
  // FFTW's MPI transform on slabs of whole z-planes. FluidSolver's layout cuts the grid into
  // those slabs, so the global vector is already in slab order ("aligned"); where it could not
  // (a rank with fewer than 2 planes, or -pressure_pc_type given) the vector is moved to the
  // slabs and back through the natural ordering.
  std::unique_ptr<SpectralPoissonPreconditioner> serial;
  std::unique_ptr<DistributedSpectralPoisson> dist;
  DM dm = nullptr;
  Vec nat = nullptr, slab = nullptr, slab_out = nullptr;
  VecScatter to_slab = nullptr;
  bool aligned = false;  ///< the DMDA's global vector is already in FFTW's slabs

  SpectralPcShell(DM da, const GridSpec& g);
  ~SpectralPcShell();
  SpectralPcShell(const SpectralPcShell&) = delete;
  SpectralPcShell& operator=(const SpectralPcShell&) = delete;

  void set_coefficients(double cx, double cy, double cz);
  /// PCShellSetApply's callback: y = M^-1 x.
  static PetscErrorCode apply(PC pc, Vec x, Vec y);
};

}  // namespace boycott::fluid
