#include "scenes/coupled_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "io/state_io.hpp"
#include "scenes/run_common.hpp"

namespace boycott::scenes {

CoupledRun::CoupledRun(const CaseParams& p, const CoupledOptions& opt) : p_(p), opt_(opt) {
  auto dc = particles::DemConfig::from_case(p);
  dc.track_drag_impulse = true;
  dem_ = std::make_unique<particles::DemSystem>(dc);
  auto fs = fluid::FluidSettings::from_case(p);
  // The fluid feels gravity (alpha_f rho_f g in set II) and, in z, the driving gradient G.
  fs.body_acceleration_m_s2 = p.gravity_vector();
  if (std::isfinite(opt.target_mean_flux_z_m_s)) fs.target_mean_flux_z_m_s = opt.target_mean_flux_z_m_s;
  fluid_ = std::make_unique<fluid::FluidSolver>(fs);
  coupler_ = std::make_unique<coupling::Coupler>(coupling::CouplingSettings::from_case(p), fs.grid);
}

double CoupledRun::particle_volume_m3() const {
  const auto& s = dem_->particles();
  double v = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) v += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i];
  return v;
}

void CoupledRun::start() {
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

CoupledStep CoupledRun::step() {
  CoupledStep st;
  const double dt_dem = p_.time.dt_dem_s;
  double dt = std::min(p_.time.dt_cfd_s, fluid_->stable_dt());
  if (opt_.move_particles) {
    st.dem_substeps = std::max(1, static_cast<int>(std::floor(dt / dt_dem + 1e-9)));
    dt = st.dem_substeps * dt_dem;
  }
  st.dt_s = dt;
  coupler_->prepare(*dem_, *fluid_, dt_prev_);
  if (opt_.move_particles) {
    for (int k = 0; k < st.dem_substeps; ++k) dem_->step();
  } else {
    // A frozen bed takes the whole drag impulse beta (u_f - v) dt (it is held in place).
    auto& s = dem_->particles();
    for (std::size_t i = 0; i < s.n_local; ++i) {
      s.drag_jx[i] = dt * s.beta[i] * (s.ufx[i] - s.vx[i]);
      s.drag_jy[i] = dt * s.beta[i] * (s.ufy[i] - s.vy[i]);
      s.drag_jz[i] = dt * s.beta[i] * (s.ufz[i] - s.vz[i]);
    }
  }
  // NaN or Inf stops the run here, before the kernels turn a position into a cell index and
  // before anything is checkpointed (the scene's last good checkpoint stays the newest).
  {
    const auto& s = dem_->particles();
    double sum = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i)
      sum += s.x[i] + s.y[i] + s.z[i] + s.vx[i] + s.vy[i] + s.vz[i] + s.wx[i] + s.wy[i] + s.wz[i];
    if (!std::isfinite(sum))
      throw PhysicsError(fmt::format("particle state became NaN or Inf at t = {:.6g} s (CFD step {}); nothing was "
                                     "checkpointed after the last good state",
                                     time_ + dt, steps_ + 1));
  }
  coupler_->deposit(*dem_, *fluid_, dt);
  if (opt_.zero_slurry_flux) {
    // Eq. 25: the fluid's flux controller finds the G that makes alpha_f <w_f> cancel the
    // particles' volume flux at the new level.
    const auto& s = dem_->particles();
    double q = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i) q += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i] * s.vz[i];
    fluid_->set_target_mean_flux_z(-q / p_.box_volume_m3());
  }
  const auto t0 = std::chrono::steady_clock::now();
  st.fluid = fluid_->step(dt);
  if (!st.fluid.converged) ++unconverged_;
  seconds_fluid_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dt_prev_ = dt;
  time_ += dt;
  ++steps_;
  const double ke = dem_->kinetic_energy_j();
  if (!std::isfinite(ke))
    throw PhysicsError(fmt::format("particle velocities became NaN at t = {:.6g} s (CFD step {})", time_, steps_));
  return st;
}

void CoupledRun::save(io::CheckpointWriter& w) const {
  w.put("run.time_s", time_);
  w.put("run.dt_prev_s", dt_prev_);
  w.put_int("run.steps", steps_);
  w.put_int("run.unconverged_fluid_steps", unconverged_);
  w.put_int("run.pressure_fallbacks", pressure_fallbacks());
  io::save(w, "dem.", dem_->export_state());
  io::save(w, "fluid.", fluid_->export_state());
  io::save(w, "coupler.", coupler_->export_state());
}

void CoupledRun::load(const io::CheckpointReader& r) {
  time_ = r.scalar("run.time_s");
  dt_prev_ = r.scalar("run.dt_prev_s");
  steps_ = r.integer("run.steps");
  // absent from checkpoints written before these counters existed
  unconverged_ = r.has("run.unconverged_fluid_steps") ? r.integer("run.unconverged_fluid_steps") : 0;
  fallbacks_before_ = (r.has("run.pressure_fallbacks") ? r.integer("run.pressure_fallbacks") : 0) - fluid_->pressure_fallbacks();
  particles::DemState ds;
  io::load(r, "dem.", ds);
  dem_->import_state(ds);
  fluid::FluidState fs;
  io::load(r, "fluid.", fs);
  const auto box = fluid_->owned_box();
  if (fs.box.lo != box.lo || fs.box.size != box.size)
    throw CheckpointError(fmt::format("{}: the fluid grid was decomposed differently (other rank count?)", r.path().string()));
  fluid_->import_state(fs);
  coupler_->import_state(io::load_arrays(r, "coupler."));
}

std::optional<double> CoupledRun::resume(const std::filesystem::path& run_dir, bool quiet,
                                         const std::function<void(const io::CheckpointReader&)>& load_scene) {
  const auto ck = io::latest_checkpoint(run_dir);
  if (!ck) return std::nullopt;
  io::CheckpointReader r(*ck);
  const std::string id = case_id(p_);
  if (r.string("case_id") != id)
    throw CheckpointError(fmt::format("{} belongs to case {}, not {}; it is left in place", ck->string(),
                                      r.string("case_id"), id));
  load(r);
  load_scene(r);
  truncate_csv_after(run_dir / "timeseries.csv", time_);
  if (!quiet) std::fprintf(stderr, "resuming from %s at t = %g s\n", ck->c_str(), time_);
  return r.scalar("run.wall_time_s");
}

void CoupledRun::checkpoint(const std::filesystem::path& run_dir, double wall_time_s,
                            const std::function<void(io::CheckpointWriter&)>& save_scene) const {
  io::CheckpointWriter w(io::checkpoint_path(run_dir, steps_));
  w.put_string("case_id", case_id(p_));
  w.put_string("case_json", to_json(p_).dump());
  w.put_string("program_version", std::string(kVersion));
  save(w);
  save_scene(w);
  w.put("run.wall_time_s", wall_time_s);
  w.commit();
  io::prune_checkpoints(run_dir, static_cast<int>(p_.output.keep_checkpoints));
}

io::SnapshotData CoupledRun::snapshot() const {
  io::SnapshotData d;
  d.time_s = time_;
  const auto& s = dem_->particles();
  const std::size_t n = s.n_local;
  for (auto [dst, src] : {std::pair{&d.x, &s.x}, {&d.y, &s.y}, {&d.z, &s.z}, {&d.vx, &s.vx}, {&d.vy, &s.vy},
                          {&d.vz, &s.vz}, {&d.radius, &s.radius}})
    dst->assign(src->begin(), src->begin() + static_cast<std::ptrdiff_t>(n));
  const auto& g = fluid_->settings().grid;
  const int nx = (int)g.n[0], ny = (int)g.n[1], nz = (int)g.n[2];
  const bool walls = !g.periodic[1];
  d.cell_fields.emplace_back("alpha_f", fluid_->gather(5));
  d.cell_fields.emplace_back("pressure", fluid_->gather(3));
  const char* names[3] = {"u", "v", "w"};
  for (int c = 0; c < 3; ++c) {
    const auto f = fluid_->gather(c);  // lower faces
    std::vector<double> cc(f.size());
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int i1 = c == 0 ? (i + 1) % nx : i, j1 = c == 1 ? j + 1 : j, k1 = c == 2 ? (k + 1) % nz : k;
          const double lo = f[i + nx * (j + ny * k)];
          double hi = 0.0;
          if (c == 1 && j1 == ny)
            hi = walls ? 0.0 : f[i + nx * (0 + ny * k)];
          else
            hi = f[i1 + nx * (j1 + ny * k1)];
          cc[i + nx * (j + ny * k)] = 0.5 * (lo + hi);
        }
    d.cell_fields.emplace_back(names[c], std::move(cc));
  }
  return d;
}

double CoupledRun::mean_particle_velocity(int c) const {
  const auto& s = dem_->particles();
  const auto& v = c == 0 ? s.vx : c == 1 ? s.vy : s.vz;
  double sum = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) sum += v[i];
  return s.n_local ? sum / static_cast<double>(s.n_local) : 0.0;
}

double CoupledRun::mean_fluid_velocity_z() const {
  const double af = 1.0 - particle_volume_m3() / p_.box_volume_m3();
  return fluid_->mean_flux_z() / af;
}

double CoupledRun::slurry_velocity_z() const {
  const auto& s = dem_->particles();
  double q = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) q += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i] * s.vz[i];
  return fluid_->mean_flux_z() + q / p_.box_volume_m3();
}

void CoupledRun::activate_models(ModelTimers& t) const {
  const auto& f = p_.forces;
  t.activate("fluid", fmt::format("set II, {}, QUICK{}", fluid_->settings().coupling_name(),
                                  p_.fluid.subgrid_model == "vreman" ? ", Vreman" : ""));
  t.activate("coupling_sample", fmt::format("kernel {}", p_.numerics.void_fraction_kernel));
  t.activate("coupling_deposit", fmt::format("kernel {}", p_.numerics.void_fraction_kernel));
  if (f.drag != "none") t.activate("drag", fmt::format("{}, implicit on both sides (timed with coupling_sample)", f.drag));
  if (f.pressure_gradient) t.activate("pressure_gradient_force", "-V_p grad P incl. G (timed with coupling_sample)");
  if (f.viscous) t.activate("viscous_force", "V_p div tau (timed with coupling_sample)");
  if (f.saffman_lift) t.activate("saffman_lift", "Eq. 16 (timed with coupling_sample)");
  if (f.added_mass) t.activate("added_mass", "Eq. 17, particle side in the mass matrix (timed with coupling_sample)");
  if (opt_.zero_slurry_flux) t.activate("slurry_flux_control", "Eq. 25 through the mean gradient G");
  if (opt_.move_particles) {
    t.activate("dem_contacts", fmt::format("{}, k_n = {} N/m, e = {}, mu = {}", p_.contact.model,
                                           p_.contact.stiffness_n_m, p_.contact.restitution, p_.contact.friction));
    if (p_.contact.rolling_model != "none" && p_.contact.rolling_friction > 0.0)
      t.activate("rolling_friction", fmt::format("{}, mu_r = {} (timed with dem_contacts)", p_.contact.rolling_model,
                                                 p_.contact.rolling_friction));
    t.activate("neighbor_search", fmt::format("linked cells + Verlet skin {} m", p_.numerics.neighbor_skin_m));
    t.activate("integration", "velocity Verlet, drag and added mass implicit");
  }
}

void CoupledRun::report_timers(ModelTimers& t) const {
  t.add("fluid", seconds_fluid_);
  t.add("coupling_sample", coupler_->seconds_sample);
  t.add("coupling_deposit", coupler_->seconds_deposit);
  if (opt_.move_particles) {
    t.add("dem_contacts", dem_->seconds_force);
    t.add("neighbor_search", dem_->seconds_neighbor);
    t.add("integration", dem_->seconds_integrate);
  }
}

}  // namespace boycott::scenes
