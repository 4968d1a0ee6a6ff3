#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "fluid/halo_exchange.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/spectral_poisson_pc.hpp"
#include "fluid/stencil_matrix.hpp"
#include "fluid/stencil_operator.hpp"
#include "fluid/vreman.hpp"

namespace boycott::fluid {

namespace {

constexpr auto check = petsc_check;
#define BC_PETSC(call) check((call), #call)

constexpr int kE[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};


/// PETSc log events of the fluid step, so that `-log_view` shows where a step's time goes beside
/// the KSP events (registered once per process, after PetscInitialize).
struct FluidEvents {
  PetscLogEvent subgrid, fluxes, momentum_assembly, momentum_sweep, pressure_assembly, continuity, correction;
};
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
class LogScope {
 public:
  explicit LogScope(PetscLogEvent e) : e_(e) { PetscLogEventBegin(e_, 0, 0, 0, 0); }
  ~LogScope() { PetscLogEventEnd(e_, 0, 0, 0, 0); }
  LogScope(const LogScope&) = delete;
  LogScope& operator=(const LogScope&) = delete;

 private:
  PetscLogEvent e_;
};

// The two algebraic multigrids for the pressure correction. BoomerAMG on one rank: it is
// deterministic, so a resumed run repeats an uninterrupted one bit for bit (GAMG's set-up is
// not: Checkpoint.ExportImportContinuesBitwise differs in the last bits with it). GAMG on
// several ranks: GMRES + BoomerAMG stops with "Error in HYPRE solver, error code 1" on 2 ranks in
// plain channel flow (t = 0.17 s of studies/cases/channel_flow.toml) where GAMG converges, and
// costs the same on the smoke case (19.4 s against 19.2 s for 0.2 s on one rank).
void set_pressure_amg(PC pc, bool boomeramg) {
#if defined(PETSC_HAVE_HYPRE)
  if (boomeramg) {
    check(PCSetType(pc, PCHYPRE), "PCSetType");
    check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
    // hypre's advice for 3-D Laplacians (HMIS coarsening, ext+i interpolation, strength 0.5,
    // 4 entries per interpolation row, one level of aggressive coarsening) in place of PETSc's
    // 2-D-minded defaults (Falgout, 0.25): setup and V-cycle are cheaper by more than the extra
    // iterations cost (bench/cfd_steps.sh: ~1180 -> ~780 ms per step). Only where the user gave
    // none of these options for this solver.
    const char* prefix = nullptr;
    check(PCGetOptionsPrefix(pc, &prefix), "PCGetOptionsPrefix");
    const std::pair<const char*, const char*> tuned[] = {{"-pc_hypre_boomeramg_coarsen_type", "HMIS"},
                                                          {"-pc_hypre_boomeramg_interp_type", "ext+i"},
                                                          {"-pc_hypre_boomeramg_strong_threshold", "0.5"},
                                                          {"-pc_hypre_boomeramg_P_max", "4"},
                                                          {"-pc_hypre_boomeramg_agg_nl", "1"}};
    for (const auto& [name, value] : tuned) {
      const std::string full = std::string("-") + (prefix ? prefix : "") + (name + 1);
      PetscBool given = PETSC_FALSE;
      check(PetscOptionsHasName(nullptr, nullptr, full.c_str(), &given), "PetscOptionsHasName");
      if (!given) check(PetscOptionsSetValue(nullptr, full.c_str(), value), "PetscOptionsSetValue");
    }
    return;
  }
#endif
  (void)boomeramg;
  check(PCSetType(pc, PCGAMG), "PCSetType");
}

/// Variable-step BDF2 weights: (c0 y^{n+1} - c1 y^n + c2 y^{n-1}) / dt with w = dt/dt_prev,
/// c0 = (1 + 2w)/(1 + w), c1 = 1 + w, c2 = w^2/(1 + w); BDF1 when there is no previous step.
void bdf_weights(double dt, double dt_prev, double c[3]) {
  if (dt_prev <= 0.0) {
    c[0] = 1.0, c[1] = 1.0, c[2] = 0.0;
    return;
  }
  const double w = dt / dt_prev;
  c[0] = (1.0 + 2.0 * w) / (1.0 + w);
  c[1] = 1.0 + w;
  c[2] = w * w / (1.0 + w);
}

}  // namespace

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
  s.pressure_relaxation = p.numerics.pressure_relaxation;
  s.cfl_max = p.numerics.cfl_max;
  s.dt_max_s = p.time.dt_cfd_s;
  s.piso = p.numerics.pressure_velocity_coupling == "piso";
  s.piso_correctors = static_cast<int>(p.numerics.piso_correctors);
  return s;
}

/// The spectral preconditioner as a PETSc PCSHELL: one application costs a few ms against
/// BoomerAMG's set-up of ~150 ms per step and ~15 ms per V-cycle. (Gathering the whole vector to
/// every rank and transforming it there made an application slower on 2 ranks than on one.)
struct SpectralPcShell {
  // One rank: the serial transform on the global vector (which is in natural order). Several:
  // FFTW's MPI transform on slabs of whole z-planes. create_layout cuts the grid into those
  // slabs, so the global vector is already in slab order ("aligned"); where it could not (a rank
  // with fewer than 2 planes, or -pressure_pc_type given) the vector is moved to the slabs and
  // back through the natural ordering.
  std::unique_ptr<SpectralPoissonPreconditioner> serial;
  std::unique_ptr<DistributedSpectralPoisson> dist;
  DM dm = nullptr;
  Vec nat = nullptr, slab = nullptr, slab_out = nullptr;
  VecScatter to_slab = nullptr;
  bool aligned = false;  ///< the DMDA's global vector is already in FFTW's slabs

  SpectralPcShell(DM da, const GridSpec& g) : dm(da) {
    const MPI_Comm comm = PetscObjectComm((PetscObject)da);
    int nranks = 1;
    MPI_Comm_size(comm, &nranks);
    const int n[3] = {(int)g.n[0], (int)g.n[1], (int)g.n[2]};
    if (nranks == 1) {
      serial = std::make_unique<SpectralPoissonPreconditioner>(n[0], n[1], n[2], g.periodic[1]);
      return;
    }
    dist = std::make_unique<DistributedSpectralPoisson>(n[0], n[1], n[2], g.periodic[1], comm);
    // Laid out in FFTW's slabs (create_layout): this rank's global block is its slab.
    PetscInt xs, ys, zs, xm, ym, zm;
    BC_PETSC(DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm));
    int aligned_here = xm == n[0] && ym == n[1] && zs == dist->z_begin() && zm == dist->z_count();
    int aligned_all = 0;
    MPI_Allreduce(&aligned_here, &aligned_all, 1, MPI_INT, MPI_MIN, comm);
    aligned = aligned_all == 1;
    if (aligned) return;
    const PetscInt plane = static_cast<PetscInt>(n[0]) * n[1];
    const PetscInt count = plane * dist->z_count(), first = plane * dist->z_begin();
    BC_PETSC(DMDACreateNaturalVector(dm, &nat));
    BC_PETSC(VecCreateMPI(comm, count, PETSC_DETERMINE, &slab));
    BC_PETSC(VecDuplicate(slab, &slab_out));
    IS is;
    BC_PETSC(ISCreateStride(comm, count, first, 1, &is));
    BC_PETSC(VecScatterCreate(nat, is, slab, is, &to_slab));
    BC_PETSC(ISDestroy(&is));
  }
  ~SpectralPcShell() {
    if (to_slab) VecScatterDestroy(&to_slab);
    if (slab) VecDestroy(&slab);
    if (slab_out) VecDestroy(&slab_out);
    if (nat) VecDestroy(&nat);
  }
  SpectralPcShell(const SpectralPcShell&) = delete;
  SpectralPcShell& operator=(const SpectralPcShell&) = delete;

  void set_coefficients(double cx, double cy, double cz) {
    if (serial) serial->set_coefficients(cx, cy, cz);
    if (dist) dist->set_coefficients(cx, cy, cz);
  }

  static PetscErrorCode apply(PC pc, Vec x, Vec y) {
    void* ctx = nullptr;
    PetscCall(PCShellGetContext(pc, &ctx));
    auto& S = *static_cast<SpectralPcShell*>(ctx);
    const PetscScalar* xa;
    PetscScalar* ya;
    if (S.serial || S.aligned) {  // one rank, or FFTW's slabs: the global vector is in transform order
      PetscCall(VecGetArrayRead(x, &xa));
      PetscCall(VecGetArray(y, &ya));
      if (S.serial)
        S.serial->apply(xa, ya);
      else
        S.dist->apply(xa, ya);
      PetscCall(VecRestoreArrayRead(x, &xa));
      PetscCall(VecRestoreArray(y, &ya));
      return 0;
    }
    PetscCall(DMDAGlobalToNaturalBegin(S.dm, x, INSERT_VALUES, S.nat));
    PetscCall(DMDAGlobalToNaturalEnd(S.dm, x, INSERT_VALUES, S.nat));
    PetscCall(VecScatterBegin(S.to_slab, S.nat, S.slab, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(S.to_slab, S.nat, S.slab, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(S.slab, &xa));
    PetscCall(VecGetArray(S.slab_out, &ya));
    S.dist->apply(xa, ya);
    PetscCall(VecRestoreArrayRead(S.slab, &xa));
    PetscCall(VecRestoreArray(S.slab_out, &ya));
    PetscCall(VecScatterBegin(S.to_slab, S.slab_out, S.nat, INSERT_VALUES, SCATTER_REVERSE));
    PetscCall(VecScatterEnd(S.to_slab, S.slab_out, S.nat, INSERT_VALUES, SCATTER_REVERSE));
    PetscCall(DMDANaturalToGlobalBegin(S.dm, S.nat, INSERT_VALUES, y));
    PetscCall(DMDANaturalToGlobalEnd(S.dm, S.nat, INSERT_VALUES, y));
    return 0;
  }
};

FluidSolver::FluidSolver(const FluidSettings& s, MPI_Comm comm) : s_(s), comm_(comm) { create_layout(); }

FluidSolver::~FluidSolver() {
  auto vd = [](Vec& v) {
    if (v) VecDestroy(&v);
  };
  for (int c = 0; c < 3; ++c) {
    for (Vec* v : {&U_[c], &Un_[c], &Unm1_[c], &alpha_[c], &Ustar_prev_[c], &D_[c], &S_[c], &K_[c], &KU_[c], &inv_diag_[c], &Ul_[c],
                   &alphal_[c], &Dl_[c], &dep_S_[c], &dep_K_[c], &dep_KU_[c], &Fl_[c]})
      vd(*v);
  }
  for (Vec* v : {&P_, &nut_, &rhs_, &sol_, &R_, &pc_, &Pl_, &nutl_, &pcl_, &dep_solid_, &nuel_}) vd(*v);
  if (null_) MatNullSpaceDestroy(&null_);
  if (ksp_m_) KSPDestroy(&ksp_m_);
  if (ksp_p_) KSPDestroy(&ksp_p_);
  spectral_pc_.reset();  // its vectors and scatter before the DM
  if (ksp_p_fallback_) KSPDestroy(&ksp_p_fallback_);
  if (A_) MatDestroy(&A_);
  for (int c = 0; c < 3; ++c) {
    opm_[c].reset();
    vd(bm_[c]);
  }
  vd(P_asm_);
  if (Ap_) MatDestroy(&Ap_);
  opA_.reset();
  opP_.reset();
  halo_.reset();
  if (dam_) DMDestroy(&dam_);
  if (da_) DMDestroy(&da_);
}

void FluidSolver::create_layout() {
  const auto& g = s_.grid;
  for (int d = 0; d < 3; ++d)
    if (g.n[d] < 2) throw InputError(fmt::format("fluid grid needs at least 2 cells per direction (got {})", g.n[d]));
  const DMBoundaryType by = g.periodic[1] ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_NONE;
  // With the spectral pressure preconditioner on several ranks, the grid is cut into FFTW's
  // slabs of whole z-planes: the global vectors are then stored in the transform's own order and
  // an application needs no scatter (with PETSc's own cut it needed four, which made it slower
  // on 2 ranks than on one). Every rank needs at least the ghost width (2) of planes.
  int nranks = 1;
  MPI_Comm_size(comm_, &nranks);
  PetscBool user_pc = PETSC_FALSE;
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-pressure_pc_type", &user_pc));
  std::vector<PetscInt> z_slabs;
  if (nranks > 1 && !user_pc) {
    for (int c : DistributedSpectralPoisson::z_slab_counts((int)g.n[0], (int)g.n[1], (int)g.n[2], comm_))
      z_slabs.push_back(c);
    if (std::any_of(z_slabs.begin(), z_slabs.end(), [](PetscInt c) { return c < 2; })) z_slabs.clear();
  }
  const PetscInt pz = z_slabs.empty() ? PETSC_DECIDE : nranks, pxy = z_slabs.empty() ? PETSC_DECIDE : 1;
  BC_PETSC(DMDACreate3d(comm_, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_BOX, (PetscInt)g.n[0],
                        (PetscInt)g.n[1], (PetscInt)g.n[2], pxy, pxy, pz, 1, 2, nullptr, nullptr,
                        z_slabs.empty() ? nullptr : z_slabs.data(), &da_));
  BC_PETSC(DMSetUp(da_));
  halo_ = std::make_unique<HaloExchange>(da_);
  const PetscInt *lx, *ly, *lz;
  PetscInt mx, my, mz;
  BC_PETSC(DMDAGetInfo(da_, nullptr, nullptr, nullptr, nullptr, &mx, &my, &mz, nullptr, nullptr, nullptr, nullptr,
                       nullptr, nullptr));
  BC_PETSC(DMDAGetOwnershipRanges(da_, &lx, &ly, &lz));
  // Same ownership, 7-point star of width 1: the matrices need no more than that.
  BC_PETSC(DMDACreate3d(comm_, DM_BOUNDARY_PERIODIC, by, DM_BOUNDARY_PERIODIC, DMDA_STENCIL_STAR, (PetscInt)g.n[0],
                        (PetscInt)g.n[1], (PetscInt)g.n[2], mx, my, mz, 1, 1, lx, ly, lz, &dam_));
  BC_PETSC(DMSetUp(dam_));
  // Both systems are applied matrix-free (stencil_operator.hpp); an AIJ copy is made only for a
  // preconditioner that needs the entries.
  opA_ = std::make_unique<StencilOperator>(dam_);
  opP_ = std::make_unique<StencilOperator>(dam_);
  PetscBool user_momentum_pc = PETSC_FALSE;
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-momentum_pc_type", &user_momentum_pc));
  momentum_aij_ = user_momentum_pc;
  pressure_aij_ = user_pc;

  auto gv = [&](Vec* v) { BC_PETSC(DMCreateGlobalVector(da_, v)); };
  auto lv = [&](Vec* v) { BC_PETSC(DMCreateLocalVector(da_, v)); };
  for (int c = 0; c < 3; ++c) {
    for (Vec* v : {&U_[c], &Un_[c], &Unm1_[c], &alpha_[c], &Ustar_prev_[c], &D_[c], &S_[c], &K_[c], &KU_[c],
                   &inv_diag_[c]})
      gv(v);
    for (Vec* v : {&Ul_[c], &alphal_[c], &Dl_[c], &dep_S_[c], &dep_K_[c], &dep_KU_[c], &Fl_[c]}) lv(v);
    BC_PETSC(VecSet(alpha_[c], 1.0));
  }
  for (Vec* v : {&P_, &nut_, &rhs_, &sol_, &R_, &pc_}) gv(v);
  for (Vec* v : {&Pl_, &nutl_, &pcl_, &dep_solid_, &nuel_}) lv(v);

  BC_PETSC(KSPCreate(comm_, &ksp_m_));
  BC_PETSC(KSPSetOptionsPrefix(ksp_m_, "momentum_"));
  BC_PETSC(KSPSetType(ksp_m_, KSPBCGS));
  BC_PETSC(KSPSetTolerances(ksp_m_, 1e-8, 1e-50, PETSC_DEFAULT, 1000));
  BC_PETSC(KSPSetInitialGuessNonzero(ksp_m_, PETSC_TRUE));
  {
    // Point Jacobi: the BDF2 term makes the momentum rows strongly diagonally dominant (one or
    // two BiCGStab iterations either way), and block Jacobi/ILU refactored the matrix for every
    // solve (~110 ms per step on the bench mesh). As a shell with the reciprocal diagonal the
    // assembly already has: PCJACOBI extracted it from the matrix at every solve (2 % of a step);
    // same arithmetic, same bits. `-momentum_pc_type` replaces it.
    PC pc;
    BC_PETSC(KSPGetPC(ksp_m_, &pc));
    BC_PETSC(PCSetType(pc, PCSHELL));
    BC_PETSC(PCShellSetContext(pc, &jacobi_inv_diag_));
    BC_PETSC(PCShellSetApply(pc, [](PC p, Vec x, Vec y) -> PetscErrorCode {
      void* ctx = nullptr;
      PetscCall(PCShellGetContext(p, &ctx));
      PetscCall(VecPointwiseMult(y, x, *static_cast<Vec*>(ctx)));
      return 0;
    }));
    BC_PETSC(PCShellSetName(pc, "point Jacobi (reciprocal diagonal from the assembly)"));
  }
  BC_PETSC(KSPSetFromOptions(ksp_m_));

  BC_PETSC(KSPCreate(comm_, &ksp_p_));
  BC_PETSC(KSPSetOptionsPrefix(ksp_p_, "pressure_"));
  // GMRES, not CG: with a packed bed at a wall (alpha_f ~ 0.45 beside 1) BoomerAMG turned out
  // not symmetric positive enough for CG (KSP_DIVERGED_INDEFINITE_PC in the demo study at 50,
  // 70 and 90 deg); GMRES converges on the same systems.
  BC_PETSC(KSPSetType(ksp_p_, KSPGMRES));
  // 1e-2 relative per SIMPLE iteration: SIMPLE iterates until the continuity residual of the
  // momentum solution is below simple_tolerance, so an exact p' each iteration buys nothing (8.5-8.75
  // SIMPLE iterations per bench step at 1e-8, 1e-3 and 1e-2 alike; 1e-8 costs ~3x the V-cycles),
  // and the final correction leaves 1e-2 of an already converged residual.
  BC_PETSC(KSPSetTolerances(ksp_p_, 1e-2, 1e-50, PETSC_DEFAULT, 1000));
  {
    PC pc;
    BC_PETSC(KSPGetPC(ksp_p_, &pc));
    if (!user_pc) {
      // The spectral preconditioner (spectral_poisson_pc.hpp, SpectralPcShell); AMG is the
      // fallback and what -pressure_pc_type hypre|gamg selects.
      spectral_pc_ = std::make_unique<SpectralPcShell>(dam_, g);
      BC_PETSC(PCSetType(pc, PCSHELL));
      BC_PETSC(PCShellSetContext(pc, spectral_pc_.get()));
      BC_PETSC(PCShellSetApply(pc, SpectralPcShell::apply));
      BC_PETSC(PCShellSetName(pc, "spectral constant-coefficient Poisson (FFT in x, z)"));
      // With this preconditioner a tighter solve is cheap (about one Krylov iteration per
      // decade) and saves SIMPLE iterations: 5.8 -> 5.0 per bench step at 1e-3 (1e-4: 5.0).
      BC_PETSC(KSPSetTolerances(ksp_p_, 1e-3, 1e-50, PETSC_DEFAULT, 1000));
      // Flexible GMRES keeps the preconditioned directions, so a solve of n iterations applies the
      // preconditioner n times; left-preconditioned GMRES also applies it to the initial residual
      // (n + 1), and an application (two FFTs) is the largest part of a solve. Same iteration
      // counts on the bench (PISO 6.0, SIMPLE 16.6 against 17.6 per step); its test is on the
      // true residual instead of the preconditioned one.
      BC_PETSC(KSPSetType(ksp_p_, KSPFGMRES));
    } else {
      set_pressure_amg(pc, nranks == 1);
    }
  }
  BC_PETSC(KSPSetFromOptions(ksp_p_));
  BC_PETSC(PetscOptionsHasName(nullptr, nullptr, "-pressure_ksp_atol", &user_pressure_atol_));
  // Periodic x, z and walls (or periodicity) in y: pure Neumann, the constant is the null space.
  BC_PETSC(MatNullSpaceCreate(comm_, PETSC_TRUE, 0, nullptr, &null_));
  BC_PETSC(MatSetNullSpace(opP_->mat(), null_));
  update_ghosts();
}

Mat FluidSolver::aij_copy(const StencilOperator& op, Mat* M) {
  if (!*M) {
    BC_PETSC(DMCreateMatrix(dam_, M));
    // Every rank writes only its own rows (StencilMatrixWriter): without this, each assembly of
    // an MPIAIJ matrix still set up the communication of off-process entries.
    BC_PETSC(MatSetOption(*M, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    BC_PETSC(MatSetOption(*M, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE));
    if (M == &Ap_) BC_PETSC(MatSetNullSpace(*M, null_));
    if (!writer_) writer_ = std::make_unique<StencilMatrixWriter>(dam_, *M);
  }
  op.copy_to(*M, *writer_);
  return *M;
}

OwnedBox FluidSolver::owned_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetCorners(da_, &xs, &ys, &zs, &xm, &ym, &zm);
  return OwnedBox{{xs, ys, zs}, {xm, ym, zm}};
}

GhostBox FluidSolver::ghost_box() const {
  PetscInt xs, ys, zs, xm, ym, zm;
  DMDAGetGhostCorners(da_, &xs, &ys, &zs, &xm, &ym, &zm);
  return GhostBox{{xs, ys, zs}, {xm, ym, zm}};
}

void FluidSolver::update_ghosts() {
  for (int c = 0; c < 3; ++c) halo_->fill(alpha_[c], alphal_[c]);
  halo_->fill(nut_, nutl_);
  update_flow_ghosts();
}

// Within a step alpha_f and nu_t are fixed; only u and p change (a ghost fill of the bench mesh
// cost ~0.3 ms with DMGlobalToLocal then, and a SIMPLE step did ~90 of them).
void FluidSolver::update_flow_ghosts() {
  for (int c = 0; c < 3; ++c) halo_->fill(U_[c], Ul_[c]);
  halo_->fill(P_, Pl_);
}

void FluidSolver::set_velocity(int c, const std::function<double(double, double, double)>& f) {
  const auto& g = s_.grid;
  const OwnedBox b = owned_box();
  PetscScalar*** u;
  BC_PETSC(DMDAVecGetArray(da_, U_[c], &u));
  for (auto k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (auto j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (auto i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        double x[3] = {(i + 0.5) * g.dx(0), (j + 0.5) * g.dx(1), (k + 0.5) * g.dx(2)};
        const std::int64_t idx[3] = {i, j, k};
        x[c] = idx[c] * g.dx(c);
        const bool wall = c == 1 && !g.periodic[1] && j == 0;
        u[k][j][i] = wall ? 0.0 : f(x[0], x[1], x[2]);
      }
  BC_PETSC(DMDAVecRestoreArray(da_, U_[c], &u));
  BC_PETSC(VecCopy(U_[c], Un_[c]));
  BC_PETSC(VecCopy(U_[c], Unm1_[c]));
  halo_->fill(U_[c], Ul_[c]);
}

void FluidSolver::set_fluid_fraction(const std::function<double(double, double, double)>& f) {
  const auto& g = s_.grid;
  const OwnedBox b = owned_box();
  PetscScalar*** a;
  double amin = 1.0, amax = 0.0;
  BC_PETSC(DMDAVecGetArray(da_, alpha_[0], &a));
  for (auto k = b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (auto j = b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (auto i = b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        const double v = f((i + 0.5) * g.dx(0), (j + 0.5) * g.dx(1), (k + 0.5) * g.dx(2));
        a[k][j][i] = v;
        amin = std::min(amin, v), amax = std::max(amax, v);
      }
  BC_PETSC(DMDAVecRestoreArray(da_, alpha_[0], &a));
  if (!(amin > 0.0) || !(amax <= 1.0))
    throw PhysicsError(fmt::format("fluid fraction outside (0, 1]: min {:.4g}, max {:.4g}", amin, amax));
  if (!alpha_initialised_ && steps_ == 0) {
    BC_PETSC(VecCopy(alpha_[0], alpha_[1]));
    BC_PETSC(VecCopy(alpha_[0], alpha_[2]));
  }
  alpha_initialised_ = true;
  for (int l = 0; l < 3; ++l) halo_->fill(alpha_[l], alphal_[l]);
}

// ---------------------------------------------------------------- coupling interface

void FluidSolver::begin_deposition() {
  if (deposition_open_) throw std::logic_error("begin_deposition called twice");
  BC_PETSC(VecZeroEntries(dep_solid_));
  BC_PETSC(DMDAVecGetArray(da_, dep_solid_, &dep_arrays_[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(dep_S_[c]));
    BC_PETSC(VecZeroEntries(dep_K_[c]));
    BC_PETSC(VecZeroEntries(dep_KU_[c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_S_[c], &dep_arrays_[1 + c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_K_[c], &dep_arrays_[4 + c]));
    BC_PETSC(DMDAVecGetArray(da_, dep_KU_[c], &dep_arrays_[7 + c]));
  }
  deposition_open_ = true;
}

PetscScalar*** FluidSolver::solid_fraction_local() { return dep_arrays_[0]; }
PetscScalar*** FluidSolver::source_local(int c) { return dep_arrays_[1 + c]; }
PetscScalar*** FluidSolver::drag_coefficient_local(int c) { return dep_arrays_[4 + c]; }
PetscScalar*** FluidSolver::drag_momentum_local(int c) { return dep_arrays_[7 + c]; }

void FluidSolver::end_deposition() {
  if (!deposition_open_) throw std::logic_error("end_deposition without begin_deposition");
  BC_PETSC(DMDAVecRestoreArray(da_, dep_solid_, &dep_arrays_[0]));
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(DMDAVecRestoreArray(da_, dep_S_[c], &dep_arrays_[1 + c]));
    BC_PETSC(DMDAVecRestoreArray(da_, dep_K_[c], &dep_arrays_[4 + c]));
    BC_PETSC(DMDAVecRestoreArray(da_, dep_KU_[c], &dep_arrays_[7 + c]));
  }
  deposition_open_ = false;
  // alpha_f = 1 - sum of deposited solid fractions.
  BC_PETSC(VecZeroEntries(R_));
  BC_PETSC(DMLocalToGlobal(da_, dep_solid_, ADD_VALUES, R_));
  BC_PETSC(VecSet(alpha_[0], 1.0));
  BC_PETSC(VecAXPY(alpha_[0], -1.0, R_));
  PetscReal amin, amax;
  BC_PETSC(VecMin(alpha_[0], nullptr, &amin));
  BC_PETSC(VecMax(alpha_[0], nullptr, &amax));
  if (!(amin > 0.0) || !(amax <= 1.0))
    throw PhysicsError(fmt::format("fluid fraction outside (0, 1] after deposition: min {:.4g}, max {:.4g}", amin,
                                   amax));
  if (!alpha_initialised_ && steps_ == 0) {
    BC_PETSC(VecCopy(alpha_[0], alpha_[1]));
    BC_PETSC(VecCopy(alpha_[0], alpha_[2]));
  }
  alpha_initialised_ = true;
  for (int l = 0; l < 3; ++l) halo_->fill(alpha_[l], alphal_[l]);
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(S_[c]));
    BC_PETSC(VecZeroEntries(K_[c]));
    BC_PETSC(VecZeroEntries(KU_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_S_[c], ADD_VALUES, S_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_K_[c], ADD_VALUES, K_[c]));
    BC_PETSC(DMLocalToGlobal(da_, dep_KU_[c], ADD_VALUES, KU_[c]));
  }
  coupling_armed_ = true;
}

void FluidSolver::clear_coupling_sources() {
  for (int c = 0; c < 3; ++c) {
    BC_PETSC(VecZeroEntries(S_[c]));
    BC_PETSC(VecZeroEntries(K_[c]));
    BC_PETSC(VecZeroEntries(KU_[c]));
  }
  coupling_armed_ = false;
}

const PetscScalar* const* const* FluidSolver::read_local(int c) {
  Vec v = c < 3 ? Ul_[c] : (c == 3 ? Pl_ : nutl_);
  BC_PETSC(DMDAVecGetArrayRead(da_, v, &read_arrays_[c]));
  return read_arrays_[c];
}

void FluidSolver::restore_read(int c) {
  Vec v = c < 3 ? Ul_[c] : (c == 3 ? Pl_ : nutl_);
  BC_PETSC(DMDAVecRestoreArrayRead(da_, v, &read_arrays_[c]));
}

// ---------------------------------------------------------------- time step

double FluidSolver::stable_dt() const {
  double rate = 0.0;  // max_c |u_c| / h_c, 1/s
  for (int c = 0; c < 3; ++c) rate = std::max(rate, max_abs_velocity(c) / s_.grid.dx(c));
  if (rate <= 0.0) return s_.dt_max_s;
  return std::min(s_.dt_max_s, s_.cfl_max / rate);
}

// The gradient is formed one (k, j) row of cells at a time in passes over i that GCC vectorises:
// every wall rule depends on j only, so it becomes a row constant (a coefficient and an offset
// per term), and the sums keep the order of the cell-by-cell form they replaced (same bits).
void FluidSolver::compute_subgrid_viscosity() {
  const LogScope log_scope(fluid_events().subgrid);
  if (!s_.vreman) {
    BC_PETSC(VecZeroEntries(nut_));
    halo_->fill(nut_, nutl_);
    return;
  }
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const std::array<double, 3> delta = {h[0], h[1], h[2]};
  const double cv = s_.vreman_constant;
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const double* u[3];
  double* nt;
  for (int c = 0; c < 3; ++c) BC_PETSC(VecGetArrayRead(Ul_[c], &u[c]));
  BC_PETSC(VecGetArray(nut_, &nt));
  const int nx = (int)b.size[0];
  row_buffers_.assign(static_cast<std::size_t>(9) * nx, 0.0);
  double* G[3][3];  // G[i][j] = d u_j / d x_i over the row
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) G[i][j] = row_buffers_.data() + (3 * i + j) * nx;
  // u_c at y-row jx is a known zero (v on the y walls); reads there are redirected to P
  auto zero = [&](int c, int jx) { return c == 1 && wall && (jx <= 0 || jx >= n1); };
  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
      for (int jc = 0; jc < 3; ++jc) {
        const double* __restrict uc = u[jc] + P0;
        {  // d u_jc / d x_jc
          const double zh = zero(jc, j + kE[jc][1]) ? 0.0 : 1.0, zl = zero(jc, j) ? 0.0 : 1.0;
          const std::int64_t oh = zh != 0.0 ? off[jc] : 0;
          const double hc = h[jc];
          double* __restrict out = G[jc][jc];
#pragma GCC ivdep
          for (int i = 0; i < nx; ++i) out[i] = (zh * uc[i + oh] - zl * uc[i]) / hc;
        }
        for (int id = 0; id < 3; ++id) {
          if (id == jc) continue;
          // d u_jc / d x_id averaged over the four edges of the cell in the (id, jc) plane:
          // term (a, s) = (f_hi u[hi] - f_lo u[lo]) / den, f and den row constants
          double fh[4], fl[4], den[4];
          std::int64_t oh[4], ol[4];
          for (int a = 0; a < 2; ++a)
            for (int s = 0; s < 2; ++s) {
              const int t = 2 * a + s;
              const std::int64_t qo = a * off[jc];  // Q = P + a e_jc
              const int qj = j + a * kE[jc][1];
              std::int64_t lo = qo - (s == 0) * off[id], hi = lo + off[id];
              int jlo = qj - (s == 0) * kE[id][1], jhi = jlo + kE[id][1];
              fh[t] = 1.0, fl[t] = 1.0, den[t] = h[id];
              if (id == 1 && wall) {
                // one-sided at the walls: u_jc = 0 (no-slip) or zero gradient (slip top)
                if (jlo < 0) {
                  fl[t] = 0.0, den[t] = 0.5 * h[1];
                } else if (jhi > n1 - 1) {
                  fh[t] = 0.0, den[t] = 0.5 * h[1];
                  if (s_.top_slip) fl[t] = 0.0;
                }
              }
              if (zero(jc, jhi)) fh[t] = 0.0;
              if (zero(jc, jlo)) fl[t] = 0.0;
              oh[t] = fh[t] != 0.0 ? hi : 0;
              ol[t] = fl[t] != 0.0 ? lo : 0;
            }
          double* __restrict out = G[id][jc];
#pragma GCC ivdep
          for (int i = 0; i < nx; ++i) {
            double sum = 0.0;
            for (int t = 0; t < 4; ++t) sum += (fh[t] * uc[i + oh[t]] - fl[t] * uc[i + ol[t]]) / den[t];
            out[i] = 0.25 * sum;
          }
        }
      }
      double* __restrict nto = nt + o0;
#pragma GCC ivdep
      for (int i = 0; i < nx; ++i) {
        const std::array<std::array<double, 3>, 3> grad = {{{G[0][0][i], G[0][1][i], G[0][2][i]},
                                                           {G[1][0][i], G[1][1][i], G[1][2][i]},
                                                           {G[2][0][i], G[2][1][i], G[2][2][i]}}};
        nto[i] = vreman_viscosity(grad, delta, cv);
      }
    }
  for (int c = 0; c < 3; ++c) BC_PETSC(VecRestoreArrayRead(Ul_[c], &u[c]));
  BC_PETSC(VecRestoreArray(nut_, &nt));
  halo_->fill(nut_, nutl_);
}

// The momentum rows read each face flux and each viscosity several times (two cells share a
// face, four share an edge); computing them once over the ghosted box costs one pass and took
// the assembly from 44 ms to 27 ms per component on the 200 x 6 x 100 bench mesh (with the flat
// indexing below; writing the values into their matrix slots took it to 10.5 ms).
void FluidSolver::compute_face_fluxes() {
  const LogScope log_scope(fluid_events().fluxes);
  const int n1 = (int)s_.grid.n[1];
  const bool wall = !s_.grid.periodic[1];
  const GhostBox gb = ghost_box();
  PetscScalar ***u[3], ***al, ***F[3];
  BC_PETSC(DMDAVecGetArray(da_, alphal_[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecGetArray(da_, Ul_[d], &u[d]));
    BC_PETSC(DMDAVecGetArray(da_, Fl_[d], &F[d]));
  }
  const int lo[3] = {(int)gb.lo[0], (int)gb.lo[1], (int)gb.lo[2]};
  const int hi[3] = {(int)(gb.lo[0] + gb.size[0]), (int)(gb.lo[1] + gb.size[1]), (int)(gb.lo[2] + gb.size[2])};
  for (int d = 0; d < 3; ++d)
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const int km = k - kE[d][2], jm = j - kE[d][1], im = i - kE[d][0];
          // the lowest ghost layer has no lower neighbour: never read (ghost width 2)
          const bool outside = km < lo[2] || jm < lo[1] || im < lo[0];
          const bool wall_face = wall && d == 1 && (j <= 0 || j >= n1);
          F[d][k][j][i] = (outside || wall_face) ? 0.0 : 0.5 * (al[k][j][i] + al[km][jm][im]) * u[d][k][j][i];
        }
  BC_PETSC(DMDAVecRestoreArray(da_, alphal_[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecRestoreArray(da_, Ul_[d], &u[d]));
    BC_PETSC(DMDAVecRestoreArray(da_, Fl_[d], &F[d]));
  }
}

void FluidSolver::compute_effective_viscosity() {
  BC_PETSC(VecCopy(nutl_, nuel_));
  BC_PETSC(VecShift(nuel_, s_.viscosity_pa_s / s_.density_kg_m3));
}

void FluidSolver::assemble_momentum(int c, double dt, double c0, double c1, double c2, bool first_iteration,
                                    StencilOperator& A) {
  const LogScope log_scope(fluid_events().momentum_assembly);
  // The component, the wall flag and QUICK as compile-time constants: the row loop's branches
  // on them fold away and the neighbour loops unroll (same arithmetic, same bits).
  const bool wall = !s_.grid.periodic[1];
  const auto run = [&](auto C, auto W, auto Q) {
    assemble_momentum_t<decltype(C)::value, decltype(W)::value, decltype(Q)::value>(dt, c0, c1, c2, first_iteration, A);
  };
  const auto by_flags = [&](auto C) {
    if (wall && s_.quick) run(C, std::true_type{}, std::true_type{});
    else if (wall) run(C, std::true_type{}, std::false_type{});
    else if (s_.quick) run(C, std::false_type{}, std::true_type{});
    else run(C, std::false_type{}, std::false_type{});
  };
  if (c == 0) by_flags(std::integral_constant<int, 0>{});
  else if (c == 1) by_flags(std::integral_constant<int, 1>{});
  else by_flags(std::integral_constant<int, 2>{});
}

// The row loop is split by neighbour (loop fission): for one (k, j) row of cells, each of the
// six neighbour terms is a pass over i that GCC vectorises, because every branch of the old
// per-cell code depends on j only (walls) and becomes a row constant, and QUICK's upwind choice
// becomes a select between loads at fixed offsets. Each coefficient is summed in the same order
// as before. The coefficients go to row buffers and from there into the operator's arrays.
template <int c, bool wall, bool use_quick>
void FluidSolver::assemble_momentum_t(double dt, double c0, double c1, double c2, bool first_iteration,
                                      StencilOperator& A) {
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const double rho = s_.density_kg_m3;
  const double lam = s_.piso ? 1.0 : s_.velocity_relaxation;  // PISO's sweeps need the unrelaxed equations
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  // Flat views: the triple-pointer DMDA arrays cost three dependent loads per value. Ghosted
  // arrays are indexed by G = (k - gz) sz + (j - gy) gx + (i - gx0), owned ones by o.
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const std::int64_t oc = off[c];
  const double *u[3], *al[3], *p, *nue, *Fd[3], *un, *unm1, *S, *K, *KU;
  double *rhs, *Dv, *prev, *idg;
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(Ul_[d], &u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(Fl_[d], &Fd[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecGetArrayRead(alphal_[l], &al[l]));
  BC_PETSC(VecGetArrayRead(Pl_, &p));
  BC_PETSC(VecGetArrayRead(nuel_, &nue));
  BC_PETSC(VecGetArrayRead(Un_[c], &un));
  BC_PETSC(VecGetArrayRead(Unm1_[c], &unm1));
  BC_PETSC(VecGetArrayRead(S_[c], &S));
  BC_PETSC(VecGetArrayRead(K_[c], &K));
  BC_PETSC(VecGetArrayRead(KU_[c], &KU));
  BC_PETSC(VecGetArray(rhs_, &rhs));
  BC_PETSC(VecGetArray(D_[c], &Dv));
  BC_PETSC(VecGetArray(Ustar_prev_[c], &prev));
  BC_PETSC(VecGetArray(inv_diag_[c], &idg));
  double* Ae[7];
  for (int e = 0; e < 7; ++e) Ae[e] = A.coef(e);

  const double* __restrict uc = u[c];
  const double* __restrict nu = nue;
  // v = 0 on the y walls (j = 0 and j = ny): a u_c node in y-row jx is a known zero
  auto zero_node = [&](int jx) -> bool { return c == 1 && wall && (jx <= 0 || jx >= n1); };
  // face node in y-row jx is inside the domain (QUICK's far upwind node may not be)
  auto face_ok = [&](int jx) -> bool {
    if (!wall) return true;
    return c == 1 ? (jx >= 0 && jx <= n1) : (jx >= 0 && jx <= n1 - 1);
  };
  const double body = s_.body_acceleration_m_s2[c] - (c == 2 ? G_ / rho : 0.0);
  const double ih[3] = {1.0 / h[0], 1.0 / h[1], 1.0 / h[2]};
  const double ih2[3] = {ih[0] * ih[0], ih[1] * ih[1], ih[2] * ih[2]};
  const double inv_dt = 1.0 / dt, inv_rho = 1.0 / rho, inv_lam = 1.0 / lam;
  const bool simplec = s_.simplec, top_slip = s_.top_slip;

  // row buffers: a_P, right-hand side, a_face, transpose stress, sum |a_nb|, 6 neighbour coefficients
  const int nx = (int)b.size[0];
  row_buffers_.assign(static_cast<std::size_t>(11) * nx, 0.0);
  double* __restrict aP = row_buffers_.data();
  double* __restrict bb = aP + nx;
  double* __restrict a1v = bb + nx;
  double* __restrict ts = a1v + nx;
  double* __restrict snb = ts + nx;
  double* anb[7] = {nullptr};
  for (int e = 1; e < 7; ++e) anb[e] = snb + e * nx;

  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
      if (c == 1 && wall && j == 0) {  // v = 0 on the wall itself: an identity row
        for (int e = 0; e < 7; ++e) std::fill(Ae[e] + o0, Ae[e] + o0 + nx, e == 0 ? 1.0 : 0.0);
        #pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          idg[o0 + i] = 1.0;
          rhs[o0 + i] = 0.0;
          if (first_iteration) Dv[o0 + i] = 0.0;
          prev[o0 + i] = 0.0;
        }
        continue;
      }
      {  // time derivative, drag, pressure gradient, body force and sources
        const double *__restrict a0 = al[0] + P0, *__restrict an = al[1] + P0, *__restrict anm = al[2] + P0;
        const double *__restrict pp = p + P0, *__restrict Ko = K + o0, *__restrict uno = un + o0;
        const double *__restrict unmo = unm1 + o0, *__restrict So = S + o0, *__restrict KUo = KU + o0;
        #pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const double a1 = 0.5 * (a0[i] + a0[i - oc]);
          const double a_n = 0.5 * (an[i] + an[i - oc]);
          const double a_nm1 = 0.5 * (anm[i] + anm[i - oc]);
          aP[i] = c0 * a1 * inv_dt + Ko[i] * inv_rho;
          double b_ = (c1 * a_n * uno[i] - c2 * a_nm1 * unmo[i]) * inv_dt;
          b_ += a1 * body - a1 * (pp[i] - pp[i - oc]) * (inv_rho * ih[c]);
          b_ += (So[i] + KUo[i]) * inv_rho;
          bb[i] = b_;
          a1v[i] = a1;
          ts[i] = 0.0;
          snb[i] = 0.0;
        }
      }
      unsigned present = 1u;  // bit e: entry e of these rows is written
      for (int d = 0; d < 3; ++d) {
        const std::int64_t od = off[d];
        for (int s = -1; s <= 1; s += 2) {
          const int e = 1 + 2 * d + (s > 0);
          const int jN = j + s * kE[d][1];
          // face flux, viscosity and transpose-stress reads of this neighbour, as offsets from P
          std::int64_t fo;                 // first flux node (the second is fo - oc or fo + oc)
          bool nb_known_zero = false;      // neighbour is a wall value v = 0 (not an unknown)
          if (d != c) {
            const int jE = s > 0 ? jN : j;  // the d-face of cell E = P + e_d (s > 0) or P
            if (d == 1 && wall && (jE <= 0 || jE >= n1)) {
              // u_c = 0 on the wall half a cell away (no-slip), or no stress (slip top); v = 0
              // there, so the transpose stress term vanishes
              if (!(s > 0 && top_slip)) {
                const double* __restrict nP = nu + P0;
                #pragma GCC ivdep
                for (int i = 0; i < nx; ++i) {
                  const double nuf = 0.5 * (nP[i] + nP[i - oc]);
                  aP[i] += 2.0 * a1v[i] * nuf * ih2[d];
                }
              }
              continue;
            }
            fo = s > 0 ? od : 0;
          } else {
            fo = s > 0 ? 0 : -oc;  // face at the cell centre Q = P or P - e_c
            nb_known_zero = zero_node(jN);
          }
          // QUICK: the upwind node is P (conv > 0) or N; its far node is P - s e_d or N + s e_d.
          // Row constants say which of those nodes exist and which are wall zeros; reads of a
          // node that does not exist or is a wall zero (v at j = ny lies outside the ghosted
          // box) are redirected to P and their value is multiplied by zero.
          const bool okN = face_ok(jN);
          const bool ok_up = face_ok(j - s * kE[d][1]) && face_ok(j) && okN;
          const bool ok_dn = face_ok(j + 2 * s * kE[d][1]) && face_ok(j) && okN;
          const double zP = zero_node(j) ? 0.0 : 1.0, zN = zero_node(jN) ? 0.0 : 1.0;
          const double zUu = zero_node(j - s * kE[d][1]) ? 0.0 : 1.0, zUd = zero_node(j + 2 * s * kE[d][1]) ? 0.0 : 1.0;
          const double qup = ok_up ? 1.0 : 0.0, qdn = ok_dn ? 1.0 : 0.0;
          const std::int64_t oN = okN && zN != 0.0 ? s * od : 0;
          const std::int64_t oUu = ok_up && zUu != 0.0 ? -s * od : 0, oUd = ok_dn && zUd != 0.0 ? 2 * s * od : 0;
          double* __restrict ae = anb[e];
          const double* __restrict uP_ = uc + P0;
          const double sh = s * 0.5;
          const double ihd = ih[d], ih2d = ih2[d], ihc = ih[c];
          if (!nb_known_zero) present |= 1u << e;
          // a weight, not a select on nb_known_zero: GCC 12 does not vectorise a select on a
          // loop-invariant bool, which left v's neighbour passes scalar (3x u's assembly time)
          const double w_nb = nb_known_zero ? 0.0 : 1.0;
          const auto tail = [&](int i, double F, double nuf, double tT) {
            ts[i] += s * tT * ih[d];
            const double dcoef = a1v[i] * nuf * ih2d;
            const double conv = F * ihd;
            aP[i] += dcoef + std::max(conv, 0.0);
            const double a = -dcoef + std::min(conv, 0.0);
            ae[i] = a;
            snb[i] += w_nb * std::abs(a);
            if constexpr (use_quick) {
              // rhs -= F (phi_QUICK - phi_upwind) / h, deferred correction
              const double vP = zP * uP_[i], vN = zN * uP_[i + oN];
              const double vUu = zUu * uP_[i + oUu], vUd = zUd * uP_[i + oUd];
              const bool up = conv > 0.0;
              const double pc = up ? vP : vN, pd = up ? vN : vP, pu = up ? vUu : vUd;
              const double ok = up ? qup : qdn;
              const double quick = 0.75 * pc + 0.375 * pd - 0.125 * pu;
              bb[i] -= ok * (conv * (quick - pc));
            }
          };
          if (d == c) {
            const double* __restrict F0 = Fd[c] + P0 + fo;
            const double* __restrict nQ = nu + P0 + fo;
            const double* __restrict uQ = uc + P0 + fo;
            const double zlo = zero_node(s > 0 ? j : j - kE[c][1]) ? 0.0 : 1.0;
            const double zhi = zero_node(s > 0 ? j + kE[c][1] : j) ? 0.0 : 1.0;
            const std::int64_t ohi = zhi != 0.0 ? oc : 0;  // v at j = ny is outside the ghosted box
            #pragma GCC ivdep
            for (int i = 0; i < nx; ++i) {
              const double F = sh * (F0[i] + F0[i + oc]);
              const double nuf = nQ[i];
              const double tT = nuf * (zhi * uQ[i + ohi] - zlo * uQ[i]) * ihc;
              tail(i, F, nuf, tT);
            }
          } else {
            const double* __restrict FE = Fd[d] + P0 + fo;
            const double* __restrict nE = nu + P0 + fo;
            const double* __restrict uE = u[d] + P0 + fo;
            #pragma GCC ivdep
            for (int i = 0; i < nx; ++i) {
              const double F = sh * (FE[i] + FE[i - oc]);
              const double nuf = 0.25 * (nE[i] + nE[i - oc] + nE[i - od] + nE[i - oc - od]);
              const double tT = nuf * (uE[i] - uE[i - oc]) * ihc;
              tail(i, F, nuf, tT);
            }
          }
        }
      }
      {
        const double* __restrict uP_ = uc + P0;
        double *__restrict rh = rhs + o0, *__restrict pv = prev + o0, *__restrict Dd = Dv + o0;
        #pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const double b_ = bb[i] + a1v[i] * ts[i];
          const double aPr = aP[i] * inv_lam;
          rh[i] = b_ + (aPr - aP[i]) * uP_[i];
          pv[i] = uP_[i];
          aP[i] = aPr;
        }
        // SIMPLE: u' = -(a/(rho a_P)) grad p'; SIMPLEC (Van Doormaal and Raithby 1984) subtracts
        // the neighbour sum, which keeps diffusion-dominated, high-aspect cells convergent.
        if (first_iteration)
          #pragma GCC ivdep
          for (int i = 0; i < nx; ++i) Dd[i] = a1v[i] / (rho * (simplec ? aP[i] - snb[i] : aP[i]));
        double* __restrict id = idg + o0;
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) id[i] = 1.0 / aP[i];
      }
      // entries of known zeros (wall values v = 0, no-slip faces) are stored as 0
      std::copy(aP, aP + nx, Ae[0] + o0);
      for (int e = 1; e < 7; ++e)
        if (present >> e & 1u) std::copy(anb[e], anb[e] + nx, Ae[e] + o0);
        else std::fill(Ae[e] + o0, Ae[e] + o0 + nx, 0.0);
    }

  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(Ul_[d], &u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(Fl_[d], &Fd[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecRestoreArrayRead(alphal_[l], &al[l]));
  BC_PETSC(VecRestoreArrayRead(Pl_, &p));
  BC_PETSC(VecRestoreArrayRead(nuel_, &nue));
  BC_PETSC(VecRestoreArrayRead(Un_[c], &un));
  BC_PETSC(VecRestoreArrayRead(Unm1_[c], &unm1));
  BC_PETSC(VecRestoreArrayRead(S_[c], &S));
  BC_PETSC(VecRestoreArrayRead(K_[c], &K));
  BC_PETSC(VecRestoreArrayRead(KU_[c], &KU));
  BC_PETSC(VecRestoreArray(rhs_, &rhs));
  BC_PETSC(VecRestoreArray(D_[c], &Dv));
  BC_PETSC(VecRestoreArray(Ustar_prev_[c], &prev));
  BC_PETSC(VecRestoreArray(inv_diag_[c], &idg));
}

void FluidSolver::apply_flux_controller() {
  if (!std::isfinite(s_.target_mean_flux_z_m_s)) return;
  const OwnedBox b = owned_box();
  PetscScalar ***w, ***al, ***Dz;
  BC_PETSC(DMDAVecGetArray(da_, U_[2], &w));
  BC_PETSC(DMDAVecGetArray(da_, alphal_[0], &al));
  BC_PETSC(DMDAVecGetArray(da_, D_[2], &Dz));
  double loc[2] = {0.0, 0.0};  // sum a_f w, sum a_f D
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        const double af = 0.5 * (al[k][j][i] + al[k - 1][j][i]);
        loc[0] += af * w[k][j][i];
        loc[1] += af * Dz[k][j][i];
      }
  double glob[2];
  MPI_Allreduce(loc, glob, 2, MPI_DOUBLE, MPI_SUM, comm_);
  const double ncell = static_cast<double>(s_.grid.cell_count());
  const double q = glob[0] / ncell, m = glob[1] / ncell;
  // w responds to G through the SIMPLE coefficient: w' = -D_z dG, so mean(a w)' = -mean(a D) dG.
  const double dG = (q - s_.target_mean_flux_z_m_s) / m;
  G_ += dG;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) w[k][j][i] -= Dz[k][j][i] * dG;
  BC_PETSC(DMDAVecRestoreArray(da_, U_[2], &w));
  BC_PETSC(DMDAVecRestoreArray(da_, alphal_[0], &al));
  BC_PETSC(DMDAVecRestoreArray(da_, D_[2], &Dz));
}

double FluidSolver::continuity_residual(double dt, double c0, double c1, double c2, Vec Rv) {
  const LogScope log_scope(fluid_events().continuity);
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  PetscScalar** *u[3], ***al[3], ***R;
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecGetArray(da_, Ul_[d], &u[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(DMDAVecGetArray(da_, alphal_[l], &al[l]));
  BC_PETSC(DMDAVecGetArray(da_, Rv, &R));
  auto flux = [&](int d, int qi, int qj, int qk) -> double {
    if (wall && d == 1 && (qj <= 0 || qj >= n1)) return 0.0;
    const double af = 0.5 * (al[0][qk][qj][qi] + al[0][qk - kE[d][2]][qj - kE[d][1]][qi - kE[d][0]]);
    return af * u[d][qk][qj][qi];
  };
  double rmax = 0.0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) {
        double r = (c0 * al[0][k][j][i] - c1 * al[1][k][j][i] + c2 * al[2][k][j][i]) / dt;
        for (int d = 0; d < 3; ++d)
          r += (flux(d, i + kE[d][0], j + kE[d][1], k + kE[d][2]) - flux(d, i, j, k)) / h[d];
        R[k][j][i] = r;
        rmax = std::max(rmax, std::abs(r));
      }
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecRestoreArray(da_, Ul_[d], &u[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(DMDAVecRestoreArray(da_, alphal_[l], &al[l]));
  BC_PETSC(DMDAVecRestoreArray(da_, Rv, &R));
  double gmax;
  MPI_Allreduce(&rmax, &gmax, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return gmax;
}

void FluidSolver::assemble_pressure() {
  const LogScope log_scope(fluid_events().pressure_assembly);
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  for (int d = 0; d < 3; ++d) halo_->fill(D_[d], Dl_[d]);
  PetscScalar** *D[3], ***al;
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecGetArray(da_, Dl_[d], &D[d]));
  BC_PETSC(DMDAVecGetArray(da_, alphal_[0], &al));
  double* Ae[7];
  for (int e = 0; e < 7; ++e) Ae[e] = opP_->coef(e);
  // coefficient a_f D / h^2 of the lower d-face of cell Q (0 on walls)
  auto coef = [&](int d, int qi, int qj, int qk) -> double {
    if (wall && d == 1 && (qj <= 0 || qj >= n1)) return 0.0;
    const double af = 0.5 * (al[qk][qj][qi] + al[qk - kE[d][2]][qj - kE[d][1]][qi - kE[d][0]]);
    return af * D[d][qk][qj][qi] / (h[d] * h[d]);
  };
  std::int64_t o = 0;
  // Mean face coefficient per direction (walls excluded), for the spectral preconditioner.
  double csum[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i, ++o) {
        double diag = 0.0;
        for (int d = 0; d < 3; ++d) {
          const double cm = coef(d, i, j, k);
          const double cp = coef(d, i + kE[d][0], j + kE[d][1], k + kE[d][2]);
          if (cm != 0.0) {
            csum[d] += cm;
            csum[3 + d] += 1.0;
          }
          diag += cm + cp;
          Ae[1 + 2 * d][o] = -cm;
          Ae[2 + 2 * d][o] = -cp;
        }
        Ae[0][o] = diag;
      }
  for (int d = 0; d < 3; ++d) BC_PETSC(DMDAVecRestoreArray(da_, Dl_[d], &D[d]));
  BC_PETSC(DMDAVecRestoreArray(da_, alphal_[0], &al));
  if (spectral_pc_) {
    double gsum[6];
    MPI_Allreduce(csum, gsum, 6, MPI_DOUBLE, MPI_SUM, comm_);
    double c[3];
    for (int d = 0; d < 3; ++d) c[d] = gsum[3 + d] > 0.0 ? gsum[d] / gsum[3 + d] : 0.0;
    spectral_pc_->set_coefficients(c[0], c[1], c[2]);
  }
  const Mat A = pressure_aij_ ? aij_copy(*opP_, &Ap_) : opP_->mat();
  BC_PETSC(KSPSetOperators(ksp_p_, A, A));
}

void FluidSolver::correct(Vec pcorr) {
  const LogScope log_scope(fluid_events().correction);
  const auto& g = s_.grid;
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  halo_->fill(pcorr, pcl_);
  PetscScalar ***pc, ***U[3], ***D[3];
  BC_PETSC(DMDAVecGetArray(da_, pcl_, &pc));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecGetArray(da_, U_[d], &U[d]));
    BC_PETSC(DMDAVecGetArray(da_, D_[d], &D[d]));
  }
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i)
        for (int d = 0; d < 3; ++d) {
          if (d == 1 && wall && j == 0) continue;
          U[d][k][j][i] -= D[d][k][j][i] * (pc[k][j][i] - pc[k - kE[d][2]][j - kE[d][1]][i - kE[d][0]]) / h[d];
        }
  BC_PETSC(DMDAVecRestoreArray(da_, pcl_, &pc));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecRestoreArray(da_, U_[d], &U[d]));
    BC_PETSC(DMDAVecRestoreArray(da_, D_[d], &D[d]));
  }
  BC_PETSC(VecAXPY(P_, s_.simplec ? 1.0 : s_.pressure_relaxation, pcorr));
}

void FluidSolver::step_simple(double dt, const double c[3], StepReport& rep) {
  const double tol = s_.simple_tolerance;
  for (int it = 0; it < s_.simple_max_iterations; ++it) {
    const bool first = it == 0;
    // max |u* - u| and max |u*| over the components: one pass each and one reduction for all
    double loc[2] = {0.0, 0.0};
    compute_face_fluxes();
    for (int cc = 0; cc < 3; ++cc) {
      assemble_momentum(cc, dt, c[0], c[1], c[2], first, *opA_);
      solve_momentum(cc, *opA_, rep);
      const double *u, *prev;
      PetscInt n;
      BC_PETSC(VecGetLocalSize(U_[cc], &n));
      BC_PETSC(VecGetArrayRead(U_[cc], &u));
      BC_PETSC(VecGetArrayRead(Ustar_prev_[cc], &prev));
      double d = loc[0], m = loc[1];
      bool nan = false;
      for (PetscInt q = 0; q < n; ++q) {
        d = std::max(d, std::abs(u[q] - prev[q]));
        m = std::max(m, std::abs(u[q]));
        nan |= std::isnan(u[q]);
      }
      // std::max drops a NaN (and MPI's MAX need not keep one): a NaN velocity counts as +inf,
      // which the continuity check below reports
      const double inf = std::numeric_limits<double>::infinity();
      loc[0] = nan ? inf : d, loc[1] = nan ? inf : m;
      BC_PETSC(VecRestoreArrayRead(U_[cc], &u));
      BC_PETSC(VecRestoreArrayRead(Ustar_prev_[cc], &prev));
    }
    double glob[2];
    MPI_Allreduce(loc, glob, 2, MPI_DOUBLE, MPI_MAX, comm_);
    const double du = glob[0], umax = glob[1];
    double flux_err = 0.0;
    if (std::isfinite(s_.target_mean_flux_z_m_s)) {
      const double q0 = mean_flux_z();
      flux_err = std::abs(q0 - s_.target_mean_flux_z_m_s) /
                 std::max({std::abs(s_.target_mean_flux_z_m_s), umax, 1e-30});
      apply_flux_controller();
    }
    rep.continuity_residual = relative_continuity_residual(dt, c, umax);
    const double uref = std::max({umax, std::abs(std::isfinite(s_.target_mean_flux_z_m_s) ? s_.target_mean_flux_z_m_s : 0.0),
                                  1e-30});
    const double dvel = du / uref;
    if (first) assemble_pressure();
    solve_pressure_correction(rep);
    rep.simple_iterations = it + 1;
    if (rep.continuity_residual < tol && dvel < tol && flux_err < tol) {
      rep.converged = true;
      break;
    }
  }
}

// PISO (Issa 1986) beside SIMPLE: one momentum solve per component with the face fluxes of the
// last step, then `piso_correctors` pressure corrections without re-assembly. Corrector k > 1
// first moves the velocity by one Jacobi sweep of the frozen momentum equations at the corrected
// pressure (u += (b(p) - A u) / a_P, which is Issa's neighbour term sum a_nb u'_nb / a_P), then
// corrects it with the same (SIMPLEC) coefficient D as SIMPLE. Nothing is iterated to a
// tolerance: the step costs one momentum round and `piso_correctors` pressure solves instead of
// ~5 of each, and its difference from SIMPLE is what tests and the work-precision study report.
void FluidSolver::step_piso(double dt, const double c[3], StepReport& rep) {
  if (!opm_[0]) {
    for (int cc = 0; cc < 3; ++cc) {
      opm_[cc] = std::make_unique<StencilOperator>(dam_);
      BC_PETSC(DMCreateGlobalVector(da_, &bm_[cc]));
    }
    BC_PETSC(DMCreateGlobalVector(da_, &P_asm_));
  }
  // The equations are linearised once, about u^n + (dt/dt_prev)(u^n - u^(n-1)): the face fluxes,
  // QUICK's deferred correction and the transposed stress are then O(dt^2) from their values
  // at u^(n+1), which keeps the step second order in time (about u^n it would be first order).
  if (steps_ > 0) {
    const double r = dt / dt_prev_;
    for (int cc = 0; cc < 3; ++cc) BC_PETSC(VecAXPBYPCZ(U_[cc], 1.0 + r, -r, 0.0, Un_[cc], Unm1_[cc]));
    update_flow_ghosts();
  }
  compute_face_fluxes();
  BC_PETSC(VecCopy(P_, P_asm_));
  const double G_asm = G_;
  for (int cc = 0; cc < 3; ++cc) {
    assemble_momentum(cc, dt, c[0], c[1], c[2], true, *opm_[cc]);
    BC_PETSC(VecCopy(rhs_, bm_[cc]));
    solve_momentum(cc, *opm_[cc], rep);
  }
  if (std::isfinite(s_.target_mean_flux_z_m_s)) apply_flux_controller();
  for (int k = 0; k < s_.piso_correctors; ++k) {
    if (k > 0) {
      momentum_sweep(G_asm);
      if (std::isfinite(s_.target_mean_flux_z_m_s)) apply_flux_controller();
    }
    rep.continuity_residual = relative_continuity_residual(dt, c, max_abs_velocity_all());
    if (k == 0) assemble_pressure();
    // Between correctors nothing reads the ghosts (the sweep works on global vectors and the
    // continuity residual refreshes u's); after the last one the coupling reads them.
    const bool last = k + 1 == s_.piso_correctors;
    solve_pressure_correction(rep, last && !std::isfinite(s_.target_mean_flux_z_m_s));
  }
  // The corrections moved the mean flux a little (mean(a_f D_z dp'/dz) is not zero where alpha_f
  // varies); the controller's response w' = -D_z dG is linear, so one more application holds
  // the target exactly, at the cost of a continuity defect of order dG d(a_f D_z)/dz.
  if (std::isfinite(s_.target_mean_flux_z_m_s)) {
    apply_flux_controller();
    update_flow_ghosts();
  }
  rep.simple_iterations = s_.piso_correctors;
  rep.converged = true;
}

void FluidSolver::momentum_sweep(double G_asm) {
  const LogScope log_scope(fluid_events().momentum_sweep);
  // p - p_asm, ghosted: the pressure the frozen right-hand sides b were assembled with
  BC_PETSC(VecWAXPY(pc_, -1.0, P_asm_, P_));
  halo_->fill(pc_, pcl_);
  const auto& g = s_.grid;
  const bool wall = !g.periodic[1];
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const double inv_rho = 1.0 / s_.density_kg_m3;
  const double *al, *dp;
  BC_PETSC(VecGetArrayRead(alphal_[0], &al));
  BC_PETSC(VecGetArrayRead(pcl_, &dp));
  for (int cc = 0; cc < 3; ++cc) {
    opm_[cc]->apply(U_[cc], sol_);  // A u
    const double *Au, *bv, *aP;
    double* u;
    BC_PETSC(VecGetArrayRead(sol_, &Au));
    BC_PETSC(VecGetArrayRead(bm_[cc], &bv));
    aP = opm_[cc]->coef(0);
    BC_PETSC(VecGetArray(U_[cc], &u));
    const std::int64_t oc = off[cc];
    const double igrad = inv_rho / g.dx(cc);
    // the mean gradient G acts like a pressure gradient on w: its change since the assembly too
    const double dbody = cc == 2 ? -(G_ - G_asm) * inv_rho : 0.0;
    std::int64_t o = 0;
    for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
      for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j) {
        const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
        const int nx = (int)b.size[0];
        if (cc == 1 && wall && j == 0) {  // identity rows: v = 0 on the wall
          o += nx;
          continue;
        }
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const std::int64_t P = P0 + i;
          const double a1 = 0.5 * (al[P] + al[P - oc]);
          const double r = bv[o + i] - Au[o + i] + a1 * (dbody - (dp[P] - dp[P - oc]) * igrad);
          u[o + i] += r / aP[o + i];
        }
        o += nx;
      }
    BC_PETSC(VecRestoreArrayRead(sol_, &Au));
    BC_PETSC(VecRestoreArrayRead(bm_[cc], &bv));
    BC_PETSC(VecRestoreArray(U_[cc], &u));
  }
  BC_PETSC(VecRestoreArrayRead(alphal_[0], &al));
  BC_PETSC(VecRestoreArrayRead(pcl_, &dp));
}

void FluidSolver::solve_momentum(int cc, const StencilOperator& op, StepReport& rep) {
  jacobi_inv_diag_ = inv_diag_[cc];
  const Mat A = momentum_aij_ ? aij_copy(op, &A_) : op.mat();
  BC_PETSC(KSPSetOperators(ksp_m_, A, A));
  BC_PETSC(VecCopy(U_[cc], sol_));
  BC_PETSC(KSPSolve(ksp_m_, rhs_, sol_));
  KSPConvergedReason reason;
  BC_PETSC(KSPGetConvergedReason(ksp_m_, &reason));
  if (reason < 0) throw PhysicsError(fmt::format("momentum solve (component {}) diverged: reason {}", cc, (int)reason));
  PetscInt its;
  BC_PETSC(KSPGetIterationNumber(ksp_m_, &its));
  rep.momentum_krylov_iterations += (int)its;
  BC_PETSC(VecCopy(sol_, U_[cc]));
}

void FluidSolver::solve_pressure_correction(StepReport& rep, bool refresh_ghosts) {
  BC_PETSC(VecScale(R_, -1.0));
  BC_PETSC(MatNullSpaceRemove(null_, R_));
  BC_PETSC(VecZeroEntries(pc_));
  // A failed solve (or a PETSc error inside the preconditioner) is redone by the other AMG:
  // BoomerAMG broke down once at 90 deg in the demo study after 1.5 s, and GAMG's aggregation
  // and BoomerAMG's coarsening fail on different systems. Counted, so a run shows how often.
  KSPConvergedReason reason = KSP_DIVERGED_PC_FAILED;
  if (!user_pressure_atol_) {
    PetscReal rtol, atol, dtol;
    PetscInt maxits;
    BC_PETSC(KSPGetTolerances(ksp_p_, &rtol, &atol, &dtol, &maxits));
    BC_PETSC(KSPSetTolerances(ksp_p_, rtol, pressure_abs_tol_, dtol, maxits));
  }
  BC_PETSC(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));  // no traceback: handled below
  PetscErrorCode solve_err = KSPSolve(ksp_p_, R_, pc_);
  BC_PETSC(PetscPopErrorHandler());
  if (!solve_err) BC_PETSC(KSPGetConvergedReason(ksp_p_, &reason));
  int failed = (solve_err || reason < 0) ? 1 : 0, any_failed = 0;
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, comm_);
  KSP used = ksp_p_;
  if (any_failed) {
    if (!ksp_p_fallback_) {
      int nranks = 1;
      MPI_Comm_size(comm_, &nranks);
      BC_PETSC(KSPCreate(comm_, &ksp_p_fallback_));
      BC_PETSC(KSPSetOptionsPrefix(ksp_p_fallback_, "pressure_fallback_"));
      BC_PETSC(KSPSetType(ksp_p_fallback_, KSPGMRES));
      BC_PETSC(KSPSetTolerances(ksp_p_fallback_, 1e-2, 1e-50, PETSC_DEFAULT, 1000));
      PC pcf;
      BC_PETSC(KSPGetPC(ksp_p_fallback_, &pcf));
      set_pressure_amg(pcf, nranks != 1);
      BC_PETSC(KSPSetFromOptions(ksp_p_fallback_));
    }
    if (!user_pressure_atol_) {
      PetscReal rtol, atol, dtol;
      PetscInt maxits;
      BC_PETSC(KSPGetTolerances(ksp_p_fallback_, &rtol, &atol, &dtol, &maxits));
      BC_PETSC(KSPSetTolerances(ksp_p_fallback_, rtol, pressure_abs_tol_, dtol, maxits));
    }
    const Mat A = aij_copy(*opP_, &Ap_);
    BC_PETSC(KSPSetOperators(ksp_p_fallback_, A, A));
    BC_PETSC(VecZeroEntries(pc_));
    BC_PETSC(KSPSolve(ksp_p_fallback_, R_, pc_));
    BC_PETSC(KSPGetConvergedReason(ksp_p_fallback_, &reason));
    if (reason < 0) throw PhysicsError(fmt::format("pressure solve diverged: reason {} (also with the fallback solver)", (int)reason));
    ++pressure_fallbacks_;
    used = ksp_p_fallback_;
  }
  PetscInt its;
  BC_PETSC(KSPGetIterationNumber(used, &its));
  rep.pressure_krylov_iterations += (int)its;
  correct(pc_);
  if (refresh_ghosts) update_flow_ghosts();
}

double FluidSolver::relative_continuity_residual(double dt, const double c[3], double umax) {
  const auto& g = s_.grid;
  const double hmin = std::min({g.dx(0), g.dx(1), g.dx(2)});
  for (int cc = 0; cc < 3; ++cc) halo_->fill(U_[cc], Ul_[cc]);
  const double rmax = continuity_residual(dt, c[0], c[1], c[2], R_);
  const double uref = std::max({umax, std::abs(std::isfinite(s_.target_mean_flux_z_m_s) ? s_.target_mean_flux_z_m_s : 0.0),
                                1e-30});
  if (!std::isfinite(rmax) || !std::isfinite(umax))
    throw PhysicsError(fmt::format("fluid velocity became NaN at t = {:.6g} s", time_));
  // The pressure correction need not reduce a residual far below what SIMPLE's test accepts
  // (rmax h / U < simple_tolerance): without a floor, a residual at round-off level (a flow
  // that already satisfies continuity, as plane Poiseuille does) can never be reduced by the
  // relative tolerance and the solve fails after its iteration limit.
  pressure_abs_tol_ = 1e-4 * s_.simple_tolerance * uref / hmin;
  return rmax * hmin / uref;
}

double FluidSolver::max_abs_velocity_all() const {
  double umax = 0.0;
  for (int cc = 0; cc < 3; ++cc) umax = std::max(umax, max_abs_velocity(cc));
  return umax;
}

StepReport FluidSolver::step(double dt) {
  if (deposition_open_) throw std::logic_error("step() inside begin/end_deposition");
  if (!(dt > 0.0)) throw std::invalid_argument("step: dt must be > 0");
  StepReport rep;
  rep.dt_s = dt;
  double c[3];
  bdf_weights(dt, steps_ > 0 ? dt_prev_ : 0.0, c);
  for (int l = 0; l < 3; ++l) halo_->fill(alpha_[l], alphal_[l]);
  compute_subgrid_viscosity();  // also refreshes nu_t's ghosts
  compute_effective_viscosity();
  update_flow_ghosts();
  if (s_.piso) {
    step_piso(dt, c, rep);
  } else {
    step_simple(dt, c, rep);
  }
  rep.mean_pressure_gradient_pa_m = G_;
  // continuity defect of the accepted fields (for diagnostics and tests)
  last_c_[0] = c[0], last_c_[1] = c[1], last_c_[2] = c[2];
  last_dt_ = dt;
  last_defect_ = continuity_residual(dt, c[0], c[1], c[2], R_);
  // rotate time levels
  for (int cc = 0; cc < 3; ++cc) {
    BC_PETSC(VecCopy(Un_[cc], Unm1_[cc]));
    BC_PETSC(VecCopy(U_[cc], Un_[cc]));
  }
  BC_PETSC(VecCopy(alpha_[1], alpha_[2]));
  BC_PETSC(VecCopy(alpha_[0], alpha_[1]));
  for (int l = 1; l < 3; ++l) halo_->fill(alpha_[l], alphal_[l]);
  time_ += dt;
  dt_prev_ = dt;
  ++steps_;
  return rep;
}

// ---------------------------------------------------------------- diagnostics

double FluidSolver::mean_flux_z() const {
  const OwnedBox b = owned_box();
  PetscScalar ***w, ***al;
  DMDAVecGetArray(da_, U_[2], &w);
  DMDAVecGetArray(da_, alphal_[0], &al);
  double loc = 0.0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i)
        loc += 0.5 * (al[k][j][i] + al[k - 1][j][i]) * w[k][j][i];
  DMDAVecRestoreArray(da_, U_[2], &w);
  DMDAVecRestoreArray(da_, alphal_[0], &al);
  double glob;
  MPI_Allreduce(&loc, &glob, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return glob / static_cast<double>(s_.grid.cell_count());
}

double FluidSolver::mean_velocity(int c) const {
  PetscScalar sum;
  VecSum(U_[c], &sum);
  return sum / static_cast<double>(s_.grid.cell_count());
}

double FluidSolver::max_abs_velocity(int c) const {
  PetscReal m;
  VecNorm(U_[c], NORM_INFINITY, &m);
  return m;
}

double FluidSolver::max_continuity_defect() const { return last_defect_; }

std::vector<double> FluidSolver::profile_y(int c) const {
  const OwnedBox b = owned_box();
  const int ny = (int)s_.grid.n[1];
  std::vector<double> loc(ny, 0.0), glob(ny, 0.0);
  PetscScalar*** u;
  DMDAVecGetArray(da_, U_[c], &u);
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j)
      for (int i = (int)b.lo[0]; i < b.lo[0] + b.size[0]; ++i) loc[j] += u[k][j][i];
  DMDAVecRestoreArray(da_, U_[c], &u);
  MPI_Allreduce(loc.data(), glob.data(), ny, MPI_DOUBLE, MPI_SUM, comm_);
  const double nxz = static_cast<double>(s_.grid.n[0] * s_.grid.n[2]);
  for (auto& v : glob) v /= nxz;
  return glob;
}

std::vector<double> FluidSolver::gather(int c) const {
  Vec src = c < 3 ? U_[c] : (c == 3 ? P_ : (c == 4 ? nut_ : alpha_[1]));
  Vec nat, all;
  VecScatter sc;
  BC_PETSC(DMDACreateNaturalVector(da_, &nat));
  BC_PETSC(DMDAGlobalToNaturalBegin(da_, src, INSERT_VALUES, nat));
  BC_PETSC(DMDAGlobalToNaturalEnd(da_, src, INSERT_VALUES, nat));
  BC_PETSC(VecScatterCreateToAll(nat, &sc, &all));
  BC_PETSC(VecScatterBegin(sc, nat, all, INSERT_VALUES, SCATTER_FORWARD));
  BC_PETSC(VecScatterEnd(sc, nat, all, INSERT_VALUES, SCATTER_FORWARD));
  PetscInt nloc;
  BC_PETSC(VecGetLocalSize(all, &nloc));
  const PetscScalar* a;
  BC_PETSC(VecGetArrayRead(all, &a));
  std::vector<double> out(a, a + nloc);
  BC_PETSC(VecRestoreArrayRead(all, &a));
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  VecDestroy(&nat);
  return out;
}

// ---------------------------------------------------------------- checkpoints

FluidState FluidSolver::export_state() const {
  FluidState st;
  st.box = owned_box();
  st.time_s = time_;
  st.dt_prev_s = dt_prev_;
  st.steps = steps_;
  st.mean_pressure_gradient_pa_m = G_;
  // nu_t too: it was computed from the previous level at the start of the last step, and the
  // coupling reads it before the next step recomputes it.
  const Vec vs[11] = {U_[0], U_[1], U_[2], Unm1_[0], Unm1_[1], Unm1_[2], P_, alpha_[1], alpha_[2], alpha_[0], nut_};
  for (Vec v : vs) {
    PetscInt nloc;
    VecGetLocalSize(v, &nloc);
    const PetscScalar* a;
    VecGetArrayRead(v, &a);
    st.fields.emplace_back(a, a + nloc);
    VecRestoreArrayRead(v, &a);
  }
  return st;
}

void FluidSolver::import_state(const FluidState& st) {
  const OwnedBox b = owned_box();
  if (st.box.lo != b.lo || st.box.size != b.size || st.fields.size() != 11)
    throw std::invalid_argument("fluid state from another layout");
  Vec vs[11] = {U_[0], U_[1], U_[2], Unm1_[0], Unm1_[1], Unm1_[2], P_, alpha_[1], alpha_[2], alpha_[0], nut_};
  for (int f = 0; f < 11; ++f) {
    PetscScalar* a;
    BC_PETSC(VecGetArray(vs[f], &a));
    std::copy(st.fields[f].begin(), st.fields[f].end(), a);
    BC_PETSC(VecRestoreArray(vs[f], &a));
  }
  for (int c = 0; c < 3; ++c) BC_PETSC(VecCopy(U_[c], Un_[c]));
  time_ = st.time_s;
  dt_prev_ = st.dt_prev_s;
  steps_ = st.steps;
  G_ = st.mean_pressure_gradient_pa_m;
  alpha_initialised_ = true;
  for (int l = 0; l < 3; ++l) halo_->fill(alpha_[l], alphal_[l]);
  halo_->fill(nut_, nutl_);
  update_ghosts();
}

}  // namespace boycott::fluid
