#include "coupling/coupled_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/timers.hpp"
#include "coupling/slab_exchange.hpp"

namespace boycott::coupling {

CoupledSystem::CoupledSystem(const CaseParams& p, const CoupledOptions& opt, MPI_Comm comm)
    : p_(p), opt_(opt) {
  auto dc = particles::DemConfig::from_case(p);
  dc.track_drag_impulse = true;
  auto fs = fluid::FluidSettings::from_case(p);
  // A particle samples and deposits up to one cell outside its slab (the window below): half a
  // cell height is as far as it may go before the next rebuild moves it to its new rank.
  dc.slab_excursion_m = 0.5 * fs.grid.dx(2);
  dem_ = std::make_unique<particles::DemSystem>(dc);
  // The fluid feels gravity (alpha_f rho_f g in set II) and, in z, the driving gradient G.
  fs.body_acceleration_m_s2 = p.gravity_vector();
  if (std::isfinite(opt.target_mean_flux_z_m_s)) fs.target_mean_flux_z_m_s = opt.target_mean_flux_z_m_s;
  MPI_Comm_size(comm, &ranks_);
  if (ranks_ > 1) check_rank_count(fs.grid, ranks_);
  fluid_ = std::make_unique<fluid::FluidSolver>(fs, comm);
  std::shared_ptr<const SlabExchange> window;
  if (ranks_ > 1) {
    // The fluid's z-slabs, which the particles follow; the window reaches the planes a
    // particle up to one cell outside the slab samples and deposits on, and the stencils that
    // derive the sampled fields (fluid_fields.cpp).
    const auto box = fluid_->owned_box();
    const int nz = static_cast<int>(fs.grid.n[2]);
    if (box.lo[0] != 0 || box.lo[1] != 0 || box.size[0] != fs.grid.n[0] || box.size[1] != fs.grid.n[1])
      throw InputError(
          fmt::format("the fluid grid is not cut into z-slabs on {} ranks: at most {} ranks for {} "
                      "planes in z",
                      ranks_, max_ranks(nz), nz));
    std::vector<int> begins(static_cast<std::size_t>(ranks_) + 1);
    const int mine = static_cast<int>(box.lo[2]);
    MPI_Allgather(&mine, 1, MPI_INT, begins.data(), 1, MPI_INT, comm);
    begins.back() = nz;
    window = std::make_shared<SlabExchange>(comm, begins, kWindowBelow, kWindowAbove);
  }
  coupler_ = std::make_unique<Coupler>(CouplingSettings::from_case(p), fs.grid, window);
}

void CoupledSystem::set_force_budget(ForceBudget* b) {
  budget_ = opt_.move_particles ? b : nullptr;
  coupler_->set_force_budget(budget_);
  dem_->wall_force_y_budget = budget_ ? &budget_->impulses(ForceBudget::walls) : nullptr;
}

int CoupledSystem::max_ranks(int nz) {
  // FFTW's slabs (its default block, ceil(nz / N) planes) with at least 2 planes on every rank.
  int best = 1;
  for (int n = 2; n <= nz; ++n) {
    const int b = (nz + n - 1) / n;
    if (nz - (n - 1) * b >= 2) best = n;
  }
  return best;
}

void CoupledSystem::check_rank_count(const GridSpec& g, int ranks) {
  const int nz = static_cast<int>(g.n[2]);
  if (ranks > max_ranks(nz))
    throw InputError(
        fmt::format("{} MPI ranks: a coupled case cuts its {} planes in z into slabs of at least 2 "
                    "planes, so at most N_max = {} ranks",
                    ranks, nz, max_ranks(nz)));
}

void CoupledSystem::decompose() {
  if (decomposed_) return;
  decomposed_ = true;
  if (ranks_ == 1) return;
  const auto box = fluid_->owned_box();
  const double hz = fluid_->settings().grid.dx(2), z0 = dem_->config().box.lo[2];
  dem_->decompose(particles::SlabDecomposition::gather(fluid_->comm(), z0 + box.lo[2] * hz,
                                                       z0 + (box.lo[2] + box.size[2]) * hz));
}

double CoupledSystem::global_sum(double local) const {
  // Before the particles are shared out, every rank holds all of them.
  return dem_->decomposition().parallel() ? particles::ordered_sum(fluid_->comm(), local) : local;
}

double CoupledSystem::particle_volume_m3() const {
  const auto& s = dem_->particles();
  double v = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i)
    v += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i];
  return global_sum(v);
}

void CoupledSystem::start() {
  decompose();
  dem_->initialize();
  coupler_->deposit(*dem_, *fluid_, 0.0);
  if (opt_.zero_slurry_flux) {
    // Weight of the suspended mixture per unit volume along z: the hydrostatic gradient.
    const double vbox = p_.box_volume_m3();
    const double ap = particle_volume_m3() / vbox;
    const double rho_mix = (1.0 - ap) * p_.fluid.density_kg_m3 + ap * p_.particles.density_kg_m3;
    fluid_->set_mean_pressure_gradient_pa_m(rho_mix * p_.gravity_vector()[2]);
  }
}

CoupledStep CoupledSystem::step() {
  CoupledStep st;
  st.dt_s = step_size(st.dem_substeps);
  if (interrupted_) throw std::logic_error("CoupledSystem::step after an interrupted step");
  // One count over ranks per step (a collective), for the test below and the stop checks.
  const double per_substep = interrupt_ ? work_per_substep() : 0.0;
  auto is_long = [&](int substeps) {
    return opt_.move_particles && interrupt_ &&
           static_cast<double>(substeps) * per_substep >= kLongStepParticleSteps;
  };
  // The state an interrupted step restarts from is the one before prepare, whose drag may still
  // shorten the step: keep it whenever the step before that shortening would be long.
  if (is_long(st.dem_substeps)) start_of_step_ = {dem_->export_state(), coupler_->export_state()};
  coupler_->prepare(*dem_, *fluid_, dt_prev_);
  limit_by_drag(st);
  stop_at_end(st);
  const bool long_step = is_long(st.dem_substeps);
  if (!advance_particles(st, long_step, per_substep)) return st;
  check_particles_finite(st.dt_s);
  coupler_->deposit(*dem_, *fluid_, st.dt_s);
  if (opt_.zero_slurry_flux) hold_zero_slurry_flux();
  wait_for_slowest_rank();
  advance_fluid(st);
  return st;
}

double CoupledSystem::step_size(int& dem_substeps) const {
  const double dt_dem = p_.time.dt_dem_s;
  double dt = std::min(p_.time.dt_cfd_s, fluid_->stable_dt());
  if (opt_.move_particles) {
    dem_substeps = whole_substeps_within(dt);
    dt = dem_substeps * dt_dem;
  }
  return dt;
}

int CoupledSystem::whole_substeps_within(double dt_s) const {
  // The 1e-9 keeps a step that is a whole number of sub-steps up to round-off at that number.
  return std::max(1, static_cast<int>(std::floor(dt_s / p_.time.dt_dem_s + 1e-9)));
}

void CoupledSystem::set_substeps(CoupledStep& st, int substeps) const {
  st.dem_substeps = substeps;
  st.dt_s = substeps * p_.time.dt_dem_s;
}

void CoupledSystem::limit_by_drag(CoupledStep& st) const {
  // Packed particles that relax past the fluid's lagged counter-flow within one step make it
  // oscillate step by step (coupling/drag_stability.hpp): the step they allow, in whole DEM
  // sub-steps, at least one.
  // A held bed does not relax, so it has no such mode.
  const double bound = coupler_->totals().drag_stable_dt_s;
  if (!opt_.move_particles || !(bound < st.dt_s)) return;
  set_substeps(st, whole_substeps_within(bound));
}

void CoupledSystem::stop_at_end(CoupledStep& st) const {
  // A step cut below time.dt_cfd (CFL, packed beds) need not divide the run: the last one ends
  // at time.end instead of a DEM sub-step or more past it. Rounded to whole sub-steps, so a run
  // whose steps divide it (time_ a sum of dt_cfd, off by round-off) keeps its last full step.
  const double left = p_.time.end_s - time_;
  if (!opt_.move_particles || !(left > 0.0)) return;
  const auto substeps = static_cast<int>(std::llround(left / p_.time.dt_dem_s));
  if (substeps < 1 || substeps >= st.dem_substeps) return;
  set_substeps(st, substeps);
}

bool CoupledSystem::advance_particles(CoupledStep& st, bool long_step, double per_substep) {
  if (!opt_.move_particles) {
    // A frozen bed takes the whole drag impulse beta (u_f - v) dt (it is held in place).
    auto& s = dem_->particles();
    const double dt = st.dt_s;
    for (std::size_t i = 0; i < s.n_local; ++i) {
      s.drag_jx[i] = dt * s.beta[i] * (s.ufx[i] - s.vx[i]);
      s.drag_jy[i] = dt * s.beta[i] * (s.ufy[i] - s.vy[i]);
      s.drag_jz[i] = dt * s.beta[i] * (s.ufz[i] - s.vz[i]);
    }
    return true;
  }
  if (long_step) {
    st.substeps_done =
        dem_->advance_interruptible(st.dem_substeps, substeps_per_check(per_substep), interrupt_);
    if (st.substeps_done < st.dem_substeps) {
      // The particles are part-way through the step and the coupler has sampled for it: only
      // the state kept at the step's start may be checkpointed.
      interrupted_ = true;
      st.interrupted = true;
      return false;
    }
  } else {
    dem_->advance(st.dem_substeps);
  }
  if (budget_) budget_->commit(dem_->particles(), st.dt_s, p_.gravity_vector()[1]);
  return true;
}

void CoupledSystem::check_particles_finite(double dt) const {
  // NaN or Inf stops the run here, before the kernels turn a position into a cell index and
  // before anything is checkpointed (the scene's last good checkpoint stays the newest).
  const auto& s = dem_->particles();
  double sum = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i)
    sum += s.x[i] + s.y[i] + s.z[i] + s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i];
  // Every rank stops together (a NaN on one rank would otherwise leave the others waiting).
  if (!std::isfinite(global_sum(sum)))
    throw PhysicsError(
        fmt::format("particle state became NaN or Inf at t = {:.6g} s (CFD step {}); nothing was "
                    "checkpointed after the last good state",
                    time_ + dt, steps_ + 1));
}

void CoupledSystem::hold_zero_slurry_flux() {
  // Eq. 25: the fluid's flux controller finds the G that makes alpha_f <w_f> cancel the
  // particles' volume flux at the new level.
  const auto& s = dem_->particles();
  double q = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i)
    q += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i] * s.vz[i];
  fluid_->set_target_mean_flux_z(-global_sum(q) / p_.box_volume_m3());
}

void CoupledSystem::wait_for_slowest_rank() {
  if (ranks_ == 1) return;
  // The particle phases end here on every rank; the time a rank waits for the slowest one is
  // its share of the load imbalance (the fluid's own collectives would hide it otherwise).
  const auto tw = std::chrono::steady_clock::now();
  MPI_Barrier(fluid_->comm());
  seconds_wait_ += seconds_since(tw);
}

void CoupledSystem::advance_fluid(CoupledStep& st) {
  const auto t0 = std::chrono::steady_clock::now();
  st.fluid = fluid_->step(st.dt_s);
  if (!st.fluid.converged) ++unconverged_;
  seconds_fluid_ += seconds_since(t0);
  dt_prev_ = st.dt_s;
  time_ += st.dt_s;
  ++steps_;
  const double ke = dem_->kinetic_energy_j();
  if (!std::isfinite(ke))
    throw PhysicsError(
        fmt::format("particle velocities became NaN at t = {:.6g} s (CFD step {})", time_, steps_));
}

double CoupledSystem::work_per_substep() const {
  return std::max(static_cast<double>(dem_->global_count()), kSubstepOverhead);
}

int CoupledSystem::substeps_per_check(double per_substep) {
  return std::max(1, static_cast<int>(kStopCheckParticleSteps / per_substep));
}

int CoupledSystem::stop_check_substeps() const {
  return substeps_per_check(work_per_substep());
}

double CoupledSystem::mean_particle_velocity(int c) const {
  const auto& s = dem_->particles();
  const auto& v = c == 0 ? s.vx : c == 1 ? s.vy : s.vz;
  double sum = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) sum += v[i];
  if (!dem_->decomposition().parallel()) return s.n_local ? sum / static_cast<double>(s.n_local) : 0.0;
  const std::int64_t n = dem_->global_count();
  return n ? global_sum(sum) / static_cast<double>(n) : 0.0;
}

double CoupledSystem::mean_fluid_velocity_z() const {
  const double af = 1.0 - particle_volume_m3() / p_.box_volume_m3();
  return fluid_->mean_flux_z() / af;
}

double CoupledSystem::slurry_velocity_z() const {
  const auto& s = dem_->particles();
  double q = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i)
    q += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i] * s.vz[i];
  return fluid_->mean_flux_z() + global_sum(q) / p_.box_volume_m3();
}

void CoupledSystem::activate_models(ModelTimers& t) const {
  const auto& f = p_.forces;
  t.activate("fluid", fmt::format("set II, {}, QUICK{}", fluid_->settings().coupling_name(),
                                  p_.fluid.subgrid_model == "vreman" ? ", Vreman" : ""));
  t.activate("coupling_sample", fmt::format("kernel {}", p_.numerics.void_fraction_kernel));
  t.activate("coupling_deposit", fmt::format("kernel {}", p_.numerics.void_fraction_kernel));
  if (f.drag != "none")
    t.activate("drag", fmt::format("{}, implicit on both sides (timed with coupling_sample)", f.drag));
  if (f.pressure_gradient)
    t.activate("pressure_gradient_force", "-V_p grad P incl. G (timed with coupling_sample)");
  if (f.viscous) t.activate("viscous_force", "V_p div tau (timed with coupling_sample)");
  if (coupler_->settings().lift == LiftLaw::saffman)
    t.activate("saffman_lift", "Eq. 16 (timed with coupling_sample)");
  if (coupler_->settings().lift == LiftLaw::saffman_mei)
    t.activate("saffman_mei_lift", "Eq. 16 times Mei's (1992) finite-Re factor (timed with coupling_sample)");
  if (coupler_->settings().lift == LiftLaw::saffman_mei_continuous)
    t.activate(
        "saffman_mei_continuous_lift",
        "Eq. 16 times Mei's (1992) factor, its jump at Re_p = 40 bridged (timed with coupling_sample)");
  if (coupler_->settings().lift == LiftLaw::mclaughlin)
    t.activate("mclaughlin_lift",
               "Eq. 16 times McLaughlin's (1991) J(epsilon) / J(inf) (timed with coupling_sample)");
  if (f.added_mass)
    t.activate("added_mass", "Eq. 17, particle side in the mass matrix (timed with coupling_sample)");
  if (opt_.zero_slurry_flux) t.activate("slurry_flux_control", "Eq. 25 through the mean gradient G");
  if (opt_.move_particles) {
    particles::activate_dem_models(t, p_);
    t.activate("integration", "velocity Verlet, drag and added mass implicit");
  }
}

CoupledCounters CoupledSystem::counters() const {
  return CoupledCounters{time_, dt_prev_, steps_, unconverged_, pressure_fallbacks()};
}

void CoupledSystem::restore_counters(const CoupledCounters& c) {
  time_ = c.time_s;
  attempt_from_s_ = c.time_s;
  dt_prev_ = c.dt_prev_s;
  steps_ = c.steps;
  unconverged_ = c.unconverged_fluid_steps;
  fallbacks_before_ = c.pressure_fallbacks - fluid_->pressure_fallbacks();
}

nlohmann::json CoupledSystem::rank_report() const {
  const std::vector<std::pair<const char*, double>> phases = {
      {"fluid", seconds_fluid_},
      {"coupling_sample", coupler_->seconds_sample},
      {"coupling_deposit", coupler_->seconds_deposit},
      {"dem_contacts", dem_->seconds_force},
      {"neighbor_search", dem_->seconds_neighbor},
      {"integration", dem_->seconds_integrate},
      {"ghost_refresh", dem_->seconds_ghosts},
      {"waiting", seconds_wait_ + dem_->seconds_wait}};
  std::vector<double> mine{static_cast<double>(dem_->particles().n_local)};
  for (const auto& ph : phases) mine.push_back(ph.second);
  const int n = static_cast<int>(mine.size());
  std::vector<double> all(static_cast<std::size_t>(n) * ranks_);
  if (ranks_ > 1)
    MPI_Allgather(mine.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, fluid_->comm());
  else
    all = mine;
  nlohmann::json j;
  j["count"] = ranks_;
  double pmin = all[0], pmax = all[0], psum = 0.0;
  nlohmann::json per = nlohmann::json::array();
  for (int r = 0; r < ranks_; ++r) {
    const double* v = all.data() + static_cast<std::size_t>(r) * n;
    pmin = std::min(pmin, v[0]), pmax = std::max(pmax, v[0]), psum += v[0];
    nlohmann::json pr;
    pr["rank"] = r;
    pr["particles"] = static_cast<std::int64_t>(v[0]);
    for (std::size_t k = 0; k < phases.size(); ++k) pr["seconds"][phases[k].first] = v[1 + k];
    per.push_back(pr);
  }
  j["particles"] = {{"min", pmin}, {"mean", psum / ranks_}, {"max", pmax}};
  j["per_rank"] = per;
  j["seconds_from_s"] = attempt_from_s_;
  return j;
}

void CoupledSystem::report_timers(ModelTimers& t) const {
  t.add("fluid", seconds_fluid_);
  t.add("coupling_sample", coupler_->seconds_sample);
  t.add("coupling_deposit", coupler_->seconds_deposit);
  if (opt_.move_particles) {
    t.add("dem_contacts", dem_->seconds_force);
    t.add("neighbor_search", dem_->seconds_neighbor);
    t.add("integration", dem_->seconds_integrate);
  }
}

}  // namespace boycott::coupling
