#pragma once
// The coupled CFD-DEM time step shared by the fluid-particle scenes (paper Fig. 2): per CFD step
// sample the fluid at the particles, sub-cycle the DEM, deposit volume and forces, set the
// driving force, solve the fluid. Scenes choose what runs: frozen particles (no DEM), the
// zero-slurry-velocity forcing of Eq. 25, which forces are on. Checkpoints, snapshots and the
// per-step output are the scenes' (scenes/coupled_checkpoint.hpp, scenes/coupled_output.hpp).
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/timers.hpp"
#include "coupling/coupler.hpp"
#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::coupling {

struct CoupledOptions {
  bool move_particles = true;    ///< false: frozen bed (ergun), no DEM steps
  bool zero_slurry_flux = true;  ///< Eq. 25: hold alpha_f <w_f> + alpha_p <w_p> = 0 through G(t)
  /// Instead of Eq. 25: hold the box mean of alpha_f w at this value (m/s) through G(t), e.g. the
  /// bulk velocity of sediment transport; NaN = off.
  double target_mean_flux_z_m_s = std::numeric_limits<double>::quiet_NaN();
};

struct CoupledStep {
  double dt_s = 0.0;
  int dem_substeps = 0;
  fluid::StepReport fluid;
  /// A stop request ended the step inside its particle sub-steps (set_interrupt): nothing of the
  /// step counts, the run's time is still the step's start, and a checkpoint written now holds
  /// the state from before the step (interrupted_state()). The run cannot step again.
  bool interrupted = false;
  int substeps_done = 0;  ///< sub-steps run before the stop was seen (interrupted only)
};

/// The run-level counters a checkpoint carries beside the engines' own states.
struct CoupledCounters {
  double time_s = 0.0, dt_prev_s = 0.0;
  std::int64_t steps = 0;
  std::int64_t unconverged_fluid_steps = 0;  ///< over the whole run, resumes included
  std::int64_t pressure_fallbacks = 0;       ///< over the whole run, resumes included
};

class CoupledSystem {
 public:
  /// comm: the ranks that share the case (PETSc's world by default).
  CoupledSystem(const CaseParams& p, const CoupledOptions& opt, MPI_Comm comm = PETSC_COMM_WORLD);

  particles::DemSystem& dem() { return *dem_; }
  const particles::DemSystem& dem() const { return *dem_; }
  fluid::FluidSolver& fluid() { return *fluid_; }
  const fluid::FluidSolver& fluid() const { return *fluid_; }
  Coupler& coupler() { return *coupler_; }
  /// Arms (or, with nullptr, disarms) the transverse force budget for the coming steps: the
  /// coupling's forces, the walls' and the contacts' (force_budget.hpp). Moving particles only.
  void set_force_budget(ForceBudget* b);
  const Coupler& coupler() const { return *coupler_; }
  const CaseParams& params() const { return p_; }

  /// After the particles are placed (every rank places all of them): keeps each rank's own,
  /// builds DEM forces, deposits alpha_f, sets the initial G to the weight of the suspended
  /// mixture (so the first step does not start from free fall).
  void start();
  /// Shares the particles among the ranks (start() does it; a resumed run, before loading).
  void decompose();
  int ranks() const { return ranks_; }
  /// A sum of the ranks' particle values in rank order (the value itself on one rank, or before
  /// the particles are shared out): the same bits on every rank.
  double global_sum(double local) const;
  /// The most MPI ranks a coupled case of nz planes in z can use (2 planes per slab).
  static int max_ranks(int nz);
  /// Throws InputError naming N_max when `ranks` exceeds it.
  static void check_rank_count(const GridSpec& g, int ranks);
  /// One CFD step of at most time.dt_cfd (CFL-limited), a whole number of DEM sub-steps.
  CoupledStep step();

  /// A stop request (collective: the same answer on every rank) that a long step asks during its
  /// particle sub-steps, every stop_check_substeps() of them. A step is long when its sub-steps
  /// times max(particles, kSubstepOverhead) reach kLongStepParticleSteps; such a step first keeps
  /// the particles' and coupler's state, so that a stop inside it can be checkpointed as of the
  /// step's start (the fluid is not touched before the sub-steps end). Shorter steps are not
  /// interrupted: they end within about kLongStepParticleSteps particle-steps of work.
  void set_interrupt(std::function<bool()> stop_requested) { interrupt_ = std::move(stop_requested); }
  static constexpr double kLongStepParticleSteps = 1e7;
  static constexpr double kStopCheckParticleSteps = 1e6;
  static constexpr double kSubstepOverhead = 64;  ///< a sub-step's fixed cost, in particle-steps
  /// Sub-steps between two stop checks of a long step: about kStopCheckParticleSteps of work.
  int stop_check_substeps() const;
  /// After an interrupted step: the particles' and coupler's state at its start (what a
  /// checkpoint holds); nullptr otherwise.
  struct StartOfStep {
    particles::DemState dem;
    std::vector<std::vector<double>> coupler;
  };
  const StartOfStep* interrupted_state() const { return interrupted_ ? &start_of_step_ : nullptr; }
  double time_s() const { return time_; }
  std::int64_t steps() const { return steps_; }
  /// Fluid steps that ended at numerics.simple_max_iterations without meeting simple_tolerance,
  /// and pressure solves redone by the fallback solver, over the whole run (resumes included).
  std::int64_t unconverged_fluid_steps() const { return unconverged_; }
  std::int64_t pressure_fallbacks() const { return fallbacks_before_ + fluid_->pressure_fallbacks(); }

  // Measurements (Eqs. 28, 25).
  double mean_particle_velocity(int c) const;  ///< <u_p,c>, m/s
  double mean_fluid_velocity_z() const;        ///< <w_f> = mean(alpha_f w) / mean(alpha_f), m/s
  double slurry_velocity_z() const;            ///< alpha_f <w_f> + alpha_p <w_p> over the box, m/s
  double particle_volume_m3() const;           ///< all ranks

  CoupledCounters counters() const;
  /// Restores the counters of a checkpoint (the engines' states are imported separately).
  void restore_counters(const CoupledCounters& c);

  /// Particles per rank (min, mean, max) and each rank's seconds per phase in this process (from
  /// simulated time "seconds_from_s": a resumed run's ranks may differ from the earlier attempts'),
  /// communication inside them; "waiting" is the time a rank waited for the others: in each DEM
  /// step's rebuild test and at the end of the particle phases. Collective; the same on every
  /// rank.
  nlohmann::json rank_report() const;
  /// Adds the wall time of each part to the timers (call once at the end).
  void report_timers(ModelTimers& t) const;
  /// Registers the active models in the timers (what this run switches on).
  void activate_models(ModelTimers& t) const;

 private:
  // The parts of step(), in order.
  /// The step (s): at most time.dt_cfd and CFL-limited, a whole number (set) of DEM sub-steps.
  double step_size(int& dem_substeps) const;
  /// The whole DEM sub-steps in dt_s (at least one), and a step set to a number of them.
  int whole_substeps_within(double dt_s) const;
  void set_substeps(CoupledStep& st, int substeps) const;
  /// Shortens the step to what the exchange of packed particles allows (numerics.drag_dt_limit).
  void limit_by_drag(CoupledStep& st) const;
  /// Shortens the last step to end at time.end.
  void stop_at_end(CoupledStep& st) const;
  /// The sub-steps (or, frozen bed, the drag impulse they would take); false when a stop request
  /// interrupted a long step.
  bool advance_particles(CoupledStep& st, bool long_step, double per_substep);
  /// Throws PhysicsError, on every rank, when a particle's state is not finite.
  void check_particles_finite(double dt) const;
  /// Eq. 25's target for the fluid's flux controller.
  void hold_zero_slurry_flux();
  /// Several ranks: the barrier that ends the particle phases, timed as waiting.
  void wait_for_slowest_rank();
  /// The fluid step, then the run's clock.
  void advance_fluid(CoupledStep& st);
  /// max(particles over all ranks, kSubstepOverhead): a sub-step's work in particle-steps (collective).
  double work_per_substep() const;
  static int substeps_per_check(double per_substep);
  // The coupling's halo of planes beyond a rank's slab (slab_exchange.hpp), below and above:
  // a particle reaches one cell past its slab face (skin/2 < one cell), its kernel one cell
  // more and the face fields one face more, and the fields are derived with one-plane stencils.
  static constexpr int kWindowBelow = 3, kWindowAbove = 4;

  CaseParams p_;
  CoupledOptions opt_;
  int ranks_ = 1;
  bool decomposed_ = false;
  std::unique_ptr<particles::DemSystem> dem_;
  std::unique_ptr<fluid::FluidSolver> fluid_;
  std::unique_ptr<Coupler> coupler_;
  double time_ = 0.0, dt_prev_ = 0.0;
  std::int64_t steps_ = 0;
  std::int64_t unconverged_ = 0, fallbacks_before_ = 0;  // counts before this process: from the checkpoint
  double seconds_fluid_ = 0.0, seconds_wait_ = 0.0;
  double attempt_from_s_ = 0.0;  ///< the simulated time this process started from (a resume's), s
  ForceBudget* budget_ = nullptr;
  std::function<bool()> interrupt_;
  StartOfStep start_of_step_;
  bool interrupted_ = false;
};

}  // namespace boycott::coupling
