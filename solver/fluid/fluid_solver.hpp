#pragma once
// Volume-averaged incompressible Navier-Stokes on a staggered (MAC) grid laid out by PETSc DMDA,
// equation set II (Zhou et al. 2010; Zeng et al. 2021, Eqs. 1-2), per unit fluid mass:
//
//   d(a)/dt + div(a u) = 0                                                        (1)
//   d(a u)/dt + div(a u u) = -a grad(p)/rho + a div(nu_eff (grad u + grad u^T)) + a g
//                            - a G e_z / rho + S/rho + K (u_p - u)/rho            (2)
//
// a = alpha_f (given, time-varying), S an explicit momentum source (N/m^3), K an implicit drag
// coefficient (kg/(m^3 s)) with the deposited particle velocity u_p, G the uniform mean
// pressure gradient in z (Pa/m) set by the flux controller, nu_eff = nu + nu_t (Vreman).
//
// Layout ("DMDA with explicit staggering"): one cell-centred DMDA (dof 1); the value stored at
// cell (i,j,k) of the u, v, w vectors lives on that cell's LOWER x, y, z face. With y walls the
// y-face j = 0 is the wall y = 0 (v = 0 kept there) and the top wall face j = ny is implicit.
// Discretisation: finite volume, BDF2 (variable step) in time, QUICK convection by deferred
// correction on implicit upwind, central diffusion and pressure gradient, SIMPLE(C) with optional
// under-relaxation; linear systems by PETSc KSP with prefixes "momentum_" and "pressure_", their
// operators applied matrix-free (stencil_operator.hpp); the solvers are set up in
// linear_solvers.hpp. Defaults: BiCGStab + point Jacobi; FGMRES + the spectral
// constant-coefficient preconditioner (spectral_poisson_pc.hpp) to 1e-3 relative per SIMPLE
// iteration, constant null space removed. `-pressure_pc_type` selects another (GMRES then), and
// BoomerAMG, prefix "pressure_fallback_", redoes a failed pressure solve.
//
// The class's members are defined by concern: fluid_solver.cpp (layout, solvers, ghosts),
// simple_piso.cpp (the step), momentum_assembly.cpp, pressure_correction.cpp,
// flux_controller.cpp, subgrid_stencil.cpp, deposition_interface.cpp and fluid_state.cpp
// (given fields, diagnostics, checkpoint state). Its data fall into one struct per concern: the
// layout, the operators, the solvers, the flow, the counters, the work vectors, the ghosted
// copies and the coupling exchange.
#include <mpi.h>
#include <petscdmda.h>
#include <petscksp.h>

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/grid_spec.hpp"
#include "fluid/fluid_settings.hpp"

namespace boycott::fluid {

class StencilMatrixWriter;
class StencilOperator;
class HaloExchange;
class SpectralPoissonPreconditioner;
struct SpectralPcShell;

/// What one step did.
struct StepReport {
  double dt_s = 0.0;
  int simple_iterations = 0;
  bool converged = false;
  int momentum_krylov_iterations = 0;  ///< summed over components and SIMPLE iterations
  int pressure_krylov_iterations = 0;  ///< summed over SIMPLE iterations
  double continuity_residual = 0.0;    ///< last max |d a/dt + div(a u*)| * h / U before correction
  double mean_pressure_gradient_pa_m = 0.0;
};

/// Owned box of this rank in cell indices: [lo, lo + size).
struct OwnedBox {
  std::array<std::int64_t, 3> lo{}, size{};
};

/// Ghosted local arrays of one rank, indexed [k][j][i] with global cell indices inside the
/// ghosted box (DMDAVecGetArray convention). Face fields use the lower-face convention above.
struct GhostBox {
  std::array<std::int64_t, 3> lo{}, size{};  ///< ghosted box (may start below 0 where periodic)
};

/// Full restart state, this rank's owned values (x fastest over the owned box).
struct FluidState {
  OwnedBox box;
  double time_s = 0.0, dt_prev_s = 0.0;
  int steps = 0;
  double mean_pressure_gradient_pa_m = 0.0;
  /// u, v, w at levels n and n-1, p, alpha_f at n, n-1 and n+1, nu_t: 11 owned arrays.
  std::vector<std::vector<double>> fields;
};

class FluidSolver {
 public:
  explicit FluidSolver(const FluidSettings& s, MPI_Comm comm = PETSC_COMM_WORLD);
  ~FluidSolver();
  FluidSolver(const FluidSolver&) = delete;
  FluidSolver& operator=(const FluidSolver&) = delete;

  const FluidSettings& settings() const { return s_; }
  OwnedBox owned_box() const;
  GhostBox ghost_box() const;
  MPI_Comm comm() const { return comm_; }

  // ---- initial and given fields (tests, scenes) ----
  /// Sets velocity component c (0 u, 1 v, 2 w) at every face from f(x, y, z) (m/s), at the
  /// current and previous time levels (a start from a steady state).
  void set_velocity(int c, const std::function<double(double, double, double)>& f);
  /// Sets alpha_f at cell centres for the NEXT step (level n+1); the first call before any step
  /// also sets levels n and n-1. Throws PhysicsError outside (0, 1].
  void set_fluid_fraction(const std::function<double(double, double, double)>& f);
  void set_body_acceleration(const std::array<double, 3>& g_m_s2) { s_.body_acceleration_m_s2 = g_m_s2; }

  // ---- coupling interface (deposition on local arrays, ADD_VALUES assembly) ----
  /// Zeroes the local deposition arrays: solid fraction (centres), explicit source S (N/m^3,
  /// faces per component), drag coefficient K (kg/(m^3 s), faces) and K u_p (N/m^3, faces).
  void begin_deposition();
  /// Writable ghosted local arrays ([k][j][i], global indices of the ghost box). Particles add
  /// their share with any kernel that stays within the ghost width (2 cells).
  PetscScalar*** solid_fraction_local();
  PetscScalar*** source_local(int c);
  PetscScalar*** drag_coefficient_local(int c);
  PetscScalar*** drag_momentum_local(int c);  ///< sum of K u_p (deposited particle velocity)
  /// Adds the local arrays of all ranks (ADD_VALUES local-to-global), sets alpha_f = 1 - solid
  /// fraction at level n+1 (PhysicsError when it leaves (0, 1]), and arms S, K, K u_p for the
  /// next step. The arrays returned above are invalid afterwards.
  void end_deposition();
  /// Switches the explicit source and drag off again (they stay armed until changed).
  void clear_coupling_sources();
  /// Flux controller target (m/s) for the mean of alpha_f w; NaN switches it off.
  void set_target_mean_flux_z(double v) { s_.target_mean_flux_z_m_s = v; }
  /// Mean pressure gradient G in z (Pa/m); set by the controller or by hand when it is off.
  double mean_pressure_gradient_pa_m() const { return flow_.G_pa_m; }
  void set_mean_pressure_gradient_pa_m(double g) { flow_.G_pa_m = g; }

  /// Read access to ghosted u, v, w (c = 0..2), p (c = 3) and nu_t (c = 4), valid until the next
  /// step; restore with restore_read().
  const PetscScalar* const* const* read_local(int c);
  void restore_read(int c);

  // ---- time stepping ----
  /// dt from CFL = max_c |u_c| dt / h_c <= cfl_max, never above dt_max_s.
  double stable_dt() const;
  /// Advances one step of size dt (s).
  StepReport step(double dt_s);
  double time_s() const { return flow_.time_s; }
  int steps_done() const { return flow_.steps; }
  /// Pressure solves that failed with the default solver and were redone by the fallback.
  int pressure_fallbacks() const { return counters_.pressure_fallbacks; }

  // ---- diagnostics ----
  /// Volume mean of alpha_f w over the domain (m/s).
  double mean_flux_z() const;
  /// Volume mean of velocity component c (m/s).
  double mean_velocity(int c) const;
  double max_abs_velocity(int c) const;
  /// max over cells of |d a/dt + div(a u)| (1/s) for the last step's levels.
  double max_continuity_defect() const;
  /// Profile of component c averaged over x and z, per y cell (c = 1: per y face), all ranks.
  std::vector<double> profile_y(int c) const;
  /// Copy of one field on all ranks in natural order (x fastest): c = 0..2 velocity, 3 p,
  /// 4 nu_t, 5 alpha_f (tests, small grids).
  std::vector<double> gather(int c) const;

  // ---- checkpoints ----
  FluidState export_state() const;
  void import_state(const FluidState& st);

 private:
  void create_layout();
  void update_ghosts();
  void update_flow_ghosts();  ///< u and p only
  void compute_subgrid_viscosity();
  void compute_face_fluxes();
  void compute_effective_viscosity();
  /// Assembles component c's momentum equations into A and work_.rhs; work_.D[c] on the first iteration of
  /// a step.
  void assemble_momentum(int c, double dt, double c0, double c1, double c2, bool first_iteration,
                         StencilOperator& A);
  template <int c, bool wall, bool use_quick>
  void assemble_momentum_t(double dt, double c0, double c1, double c2, bool first_iteration,
                           StencilOperator& A);
  void step_simple(double dt, const double c[3], StepReport& rep);
  /// Creates each component's operator and right-hand side, kept for corrector sweeps.
  void keep_momentum_operators();
  /// SIMPLE with several correctors solves its inner systems to a fixed reduction per iteration
  /// (simple_piso.cpp); one corrector and PISO keep the tolerances they always had.
  bool inexact_inner_solves() const { return !s_.piso && s_.simple_correctors > 1; }
  void step_piso(double dt, const double c[3], StepReport& rep);
  /// Solves component cc's momentum equations from the guess flow_.U[cc]; the solution is left in work_.sol.
  void solve_momentum(int cc, const StencilOperator& A, StepReport& rep);
  /// The AIJ copy of op in *M (created on first use), for preconditioners that need entries.
  Mat aij_copy(const StencilOperator& op, Mat* M);
  /// Pressure correction from the continuity residual in work_.R, then the velocity and pressure
  /// update (and their ghosts unless told otherwise).
  void solve_pressure_correction(StepReport& rep, bool refresh_ghosts = true);
  /// max |d a/dt + div(a u)| h_min / U of flow_.U (also refreshes the ghosted velocities).
  double relative_continuity_residual(double dt, const double c[3], double umax);
  double max_abs_velocity_all() const;
  /// PISO: one Jacobi sweep of the frozen momentum equations at the current pressure.
  void momentum_sweep(double G_asm);
  void apply_flux_controller();
  double continuity_residual(double dt, double c0, double c1, double c2, Vec R);
  void assemble_pressure();
  void correct(Vec pcorr);

  FluidSettings s_;
  MPI_Comm comm_;

  /// The grid's layout on the ranks: its DMDAs and the ghost fills.
  struct Layout {
    DM da = nullptr;                     // box stencil, width 2: ghosted fields
    DM dam = nullptr;                    // star stencil, width 1, same ownership: matrices
    std::unique_ptr<HaloExchange> halo;  // ghost fills of da's local vectors
  };
  Layout layout_;

  /// The linear operators, applied matrix-free (stencil_operator.hpp), and their AIJ copies.
  struct Operators {
    std::unique_ptr<StencilOperator> momentum;  // one component at a time
    std::unique_ptr<StencilOperator> pressure;  // the pressure correction's
    // PISO and SIMPLE with several correctors: each component's operator and right-hand side,
    // kept for the corrector sweeps, and the pressure they were assembled with
    std::unique_ptr<StencilOperator> frozen[3];
    Vec frozen_rhs[3]{}, frozen_pressure = nullptr;
    // AIJ copies of the operators, made only for preconditioners that need the entries
    // (-momentum_pc_type, -pressure_pc_type, the pressure fallback); the writer knows their slots
    bool momentum_needs_aij = false, pressure_needs_aij = false;
    Mat momentum_aij = nullptr, pressure_aij = nullptr;
    std::unique_ptr<StencilMatrixWriter> writer;
  };
  Operators ops_;

  /// The linear solvers of a step (linear_solvers.hpp) and how they are steered.
  struct Solvers {
    KSP momentum = nullptr, pressure = nullptr;
    KSP pressure_fallback = nullptr;  // BoomerAMG, created on the first failed pressure solve
    // The pressure preconditioner on one rank unless the user picks another (-pressure_pc_type).
    std::unique_ptr<SpectralPcShell> spectral_pc;
    // Absolute tolerance of the pressure solves (1/s), from the last continuity test's scale;
    // a user's -pressure_ksp_atol replaces it.
    double pressure_abs_tol = 0.0;
    PetscBool user_pressure_atol = PETSC_FALSE;
    PetscBool user_momentum_atol = PETSC_FALSE;
    // whether the momentum floor is taken in the Jacobi-scaled norm: -1 until the first solve
    int momentum_floor_jacobi = -1;
    MatNullSpace null_space = nullptr;  // constants, the pressure's null space
  };
  Solvers solvers_;

  /// The flow: what a checkpoint carries (fluid_state.cpp) and the level before it.
  struct Flow {
    Vec U[3]{}, Un[3]{}, Unm1[3]{}, P = nullptr;  // velocity at n+1, n, n-1 (m/s); pressure (Pa)
    Vec alpha[3]{};                               // fluid fraction: [0] n+1, [1] n, [2] n-1
    Vec nut = nullptr;                            // subgrid viscosity, m^2/s
    double time_s = 0.0;
    double dt_prev_s = 0.0;  // the last step's, for the second-order time derivative
    int steps = 0;
    double G_pa_m = 0.0;             // the mean pressure gradient driving the flow
    bool alpha_initialised = false;  // alpha_f was set (levels n and n-1 too, before the first step)
  };
  Flow flow_;

  /// What the last step did, for its report and the run's.
  struct Counters {
    int pressure_fallbacks = 0;
    double last_dt_s = 0.0;
    double last_defect = 0.0;
    int momentum_its = 0;
  };
  Counters counters_;

  /// The global work vectors of the pressure-velocity iteration.
  struct Work {
    Vec D[3]{};                        // a_face / (rho a_P') per face (SIMPLE correction coefficient)
    Vec inv_diag[3]{};                 // 1 / diagonal of each component's momentum matrix (Jacobi)
    Vec jacobi_inv_diag = nullptr;     // the one the momentum solve in progress uses
    Vec rhs = nullptr, sol = nullptr;  // a momentum system's right-hand side and solution
    Vec R = nullptr, pc = nullptr;     // continuity residual, pressure correction
    std::vector<double> row_buffers;   // momentum assembly and subgrid stencil, one (k, j) row of cells
  };
  Work work_;

  /// Ghosted local vectors of da, read by the stencils.
  struct Ghosts {
    Vec U[3]{}, P = nullptr, alpha[3]{}, nut = nullptr, pc = nullptr, D[3]{};
    // per SIMPLE iteration: a_f u_d on each lower d-face (0 on walls), m/s; per step: nu + nu_t, m^2/s
    Vec F[3]{}, nue = nullptr;
  };
  Ghosts ghosts_;

  /// The coupling interface: the local deposition arrays, the sources they arm on the faces, and
  /// the read views of the ghosted fields.
  struct CouplingExchange {
    Vec dep_solid = nullptr, dep_S[3]{}, dep_K[3]{}, dep_KU[3]{};  // ghosted local, summed into S, K, KU
    PetscScalar*** dep_arrays[10]{};
    bool open = false;            // between begin_deposition and end_deposition
    Vec S[3]{}, K[3]{}, KU[3]{};  // explicit source, drag coefficient and K u_p on faces
    bool armed = false;           // S, K, KU hold a deposition
    PetscScalar*** read_arrays[5]{};
  };
  CouplingExchange coupling_;
};

}  // namespace boycott::fluid
