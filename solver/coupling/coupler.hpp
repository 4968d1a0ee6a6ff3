#pragma once
// Two-way fluid-particle coupling of one CFD step (paper section II C, Fig. 2):
//
//   prepare():  sample the fluid at every particle with its kernel weights and set the particle
//               side of the coupling hook: implicit drag (beta, u_f), added mass in the mass
//               matrix, and the explicit forces -V_p grad P (G included), V_p div tau, Saffman
//               lift and the fluid half of the added mass. They stay fixed over the DEM sub-steps.
//   (the caller sub-cycles the DEM over the CFD step)
//   deposit():  particle volume -> alpha_f; drag onto the fluid momentum matrix (K on the
//               diagonal, K u_p on the right side, u_p the particle velocity averaged over the
//               sub-steps); the reactions to Saffman and added mass as an explicit source (Eq. 19).
//
// The pressure-gradient and viscous forces are not fed back (equation set II: the fluid feels
// them through alpha_f). Every exchanged force uses one set of face weights per particle, so what
// the particles receive the fluid gives back exactly, up to one time-level lag: over a sub-cycle
// the particles see the fluid at level n while the fluid's implicit drag and its alpha-weighted
// pressure and viscous terms act at level n+1. The next prepare() measures that difference
// (totals().lag_impulse_ns, both levels sampled with the same weights), so a momentum budget
// closes to round-off with it; it is not fed back (see coupler_sample.cpp). It is bounded: for a
// steady state it vanishes, and over a run it sums to roughly the difference of its end values.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/case_params.hpp"
#include "core/grid_spec.hpp"
#include "coupling/fluid_fields.hpp"
#include "coupling/force_budget.hpp"
#include "coupling/kernels.hpp"
#include "coupling/lift_laws.hpp"
#include "coupling/sampling.hpp"
#include "coupling/slab_exchange.hpp"

namespace boycott::particles {
class DemSystem;
struct ParticleStore;
}  // namespace boycott::particles
namespace boycott::fluid {
class FluidSolver;
}

namespace boycott::coupling {

struct CouplingSettings {
  std::string drag = "difelice_paper";
  LiftLaw lift = LiftLaw::saffman;  ///< none: no lift (and no vorticity sampled)
  bool added_mass = true, pressure_gradient = true, viscous = true;
  KernelKind kernel = KernelKind::trilinear_smoothed;
  Sampling sampling = Sampling::kernel;  ///< how the fluid is read at the particles (sampling.hpp)
  bool edge_vorticity = false;           ///< numerics.vorticity = "edges" (fluid_fields.hpp)
  bool drag_dt_limit = false;            ///< numerics.drag_dt_limit: prepare finds drag_stable_dt_s
  double rho_f_kg_m3 = 1000.0, mu_pa_s = 1.0e-3;
  bool top_slip = false;
  /// The case's [forces], [fluid], numerics.void_fraction_kernel and numerics.sampling.
  static CouplingSettings from_case(const CaseParams& p);
};

/// Totals of the last deposit, for diagnostics and conservation tests.
struct ExchangeTotals {
  double solid_volume_m3 = 0.0;        ///< sum over cells of (1 - alpha_f) V_cell
  std::array<double, 3> reaction_n{};  ///< explicit force given to the fluid (Saffman, added mass), N
  /// Momentum the last step's time-level lag created (fluid at n+1 against particles at n),
  /// measured by prepare, N s.
  std::array<double, 3> lag_impulse_ns{};
  /// numerics.sampling = "trilinear": the particles read the fluid with other weights than the
  /// kernel that deposits their drag coefficient, momentum and volume, so what the fluid gives
  /// (kernel weights) and what the particles receive (sampling weights) differ by
  /// dt (beta (u_kernel - u_sampled) + F_pv,kernel - F_pv,sampled), with u and the pressure and
  /// viscous force F_pv read at the new level. Measured by prepare beside the lag (N s), not fed
  /// back; zero with "kernel". A momentum budget closes with lag + mismatch.
  std::array<double, 3> sampling_mismatch_ns{};
  /// Largest CFD step the exchange of the last prepare's packed particles stays stable at
  /// (drag_stability.hpp), s; infinity with none, or with numerics.drag_dt_limit off.
  double drag_stable_dt_s = std::numeric_limits<double>::infinity();
  double min_alpha_f = 1.0;  ///< smallest and largest cell fluid fraction after the last deposit
  double max_alpha_f = 1.0;
};

class Coupler {
 public:
  /// window: on several ranks, the planes this rank samples and deposits on (the fluid's
  /// z-slabs with their halo, slab_exchange.hpp); nullptr on one rank.
  Coupler(const CouplingSettings& s, const GridSpec& g, std::shared_ptr<const SlabExchange> window = nullptr);

  /// Samples the fluid's current level (dt_prev_s: the step that led to it, for Du/Dt) and sets
  /// beta, u_f, ext and madd on every local particle.
  void prepare(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_prev_s);
  /// Deposits particle volume and the coupling forces of a sub-cycle of length dt_s (0: volume
  /// only, at start-up) and arms them in the fluid for its next step.
  void deposit(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_s);

  /// Over all ranks.
  const ExchangeTotals& totals() const { return totals_; }
  /// While set, prepare() adds each particle's fluid forces to the budget (output.force_budget_y).
  void set_force_budget(ForceBudget* b) { budget_ = b; }
  /// The deposited solid fraction per cell (last deposit), x fastest: this rank's window.
  const GridField& solid_fraction() const { return solid_; }
  const FluidFields& fields() const { return fields_; }
  const CouplingSettings& settings() const { return s_; }

  /// What the next step depends on (checkpoints): the fluid velocity read at the last prepare
  /// (previous level for Du/Dt) and the deposited solid fraction (alpha_f at the particles),
  /// over the whole grid (collective: gathered to rank 0 on several ranks). The per-particle
  /// force of that prepare (lag measurement) is on the particles.
  std::vector<std::vector<double>> export_state() const;
  /// Every rank passes the whole state. A state of earlier versions (8 arrays, the force per
  /// particle id among them) puts that force on the particles of `dem`.
  void import_state(const std::vector<std::vector<double>>& st, particles::DemSystem& dem);

  /// Drag coefficient of the last prepare per particle in storage order is on the particles
  /// (beta); these are the time spent, s.
  double seconds_sample = 0.0, seconds_deposit = 0.0;

 private:
  struct Stencil {
    Weights1D cell[3], face[3];
    int z_image = 0;  ///< planes added to the kernel's z indices to reach this rank's window
  };
  /// Trilinear sampling weights (sampling.hpp): x and z at cell centres [0] and faces [1]; y per
  /// wall rule.
  struct LinearStencil {
    Weights1D x[2], z[2];
    Weights1D y_tangential, y_normal, y_centre_extrapolated, y_face_extrapolated, y_alpha;
  };
  Stencil stencil(double x, double y, double z) const;
  LinearStencil linear_stencil(double x, double y, double z, int z_image) const;
  // prepare (coupler_sample.cpp): per particle, the face fields, the cell-centred ones, the
  // explicit forces from them and the force budget's share.
  template <class Law>
  void prepare_impl(const Law& law, particles::DemSystem& dem, double dt_prev_s);
  struct FaceSample;
  /// The face fields with the kernel's weights (vp: the particle's volume, m^3).
  void sample_faces_kernel(const Stencil& st, double vp, FaceSample& f) const;
  /// The face fields with the trilinear weights, and with the kernel's for the mismatch.
  void sample_faces_trilinear(const Stencil& st, const LinearStencil& ls, double vp, FaceSample& f) const;
  /// The solid fraction (returned) and, where the lift needs it, the vorticity w (1/s).
  double sample_solid_and_vorticity(const Stencil& st, const LinearStencil& ls, bool linear,
                                    double (&w)[3]) const;
  /// Lift and added mass added to the sampled force fe (N), their reactions to react, the lift to
  /// fl; sets the particle's added mass and explicit force.
  void add_explicit_forces(particles::ParticleStore& p, std::size_t i, const double (&slip)[3],
                           const double (&w)[3], double d, double vp, const FaceSample& f, double (&fe)[3],
                           double (&react)[3], double (&fl)[3]) const;
  void add_to_budget(double y, const double (&fl)[3], const FaceSample& f, double madd, double slip,
                     const double (&w)[3], double d) const;
  // deposit (coupler_deposit.cpp).
  /// Every local particle's volume and (dt_s > 0) drag and reactions onto this rank's arrays;
  /// returns the sum of the reactions (N).
  std::vector<double> deposit_particles(particles::DemSystem& dem, double dt_s);
  void deposit_drag(const Stencil& st, const particles::ParticleStore& p, std::size_t i,
                    const double (&rf)[3], double dt_s);
  /// This rank's planes into the fluid's deposition arrays.
  void add_solid_fraction(fluid::FluidSolver& fs, const std::vector<double>& solid) const;
  void add_drag_and_sources(fluid::FluidSolver& fs, int c) const;
  void record_alpha_range(const std::vector<double>& solid);
  /// The owned planes of a windowed field, summed over every rank's window (several ranks).
  std::vector<double> sum_owned(const GridField& f) const;
  /// A field's own planes gathered over all ranks to rank 0 (the whole grid on one rank).
  std::vector<double> gather_whole(const GridField& f) const;
  /// Every rank's own planes (in plane order) gathered to rank 0 (several ranks).
  std::vector<double> gather_planes(const std::vector<double>& own) const;

  CouplingSettings s_;
  GridSpec g_;
  std::shared_ptr<const SlabExchange> window_;
  FluidFields fields_;
  GridField solid_;
  // Per velocity component: the layout of its face nodes (`a` unused), and the drag coefficient
  // K, the drag momentum K u_p and the explicit source S deposited there, interleaved per node
  // (the deposit adds all three at each node it visits: one cache line instead of three).
  GridField face_layout_[3];
  std::vector<double> drag_[3];
  ExchangeTotals totals_;
  ForceBudget* budget_ = nullptr;
};

}  // namespace boycott::coupling
