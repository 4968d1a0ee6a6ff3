// Scene dem_only: the particle phase alone (no fluid is solved), optionally with a linear Stokes
// drag against still fluid, F = -3 pi mu d v, applied through the engine's implicit drag hook.
// Measures the mean particle velocity history and the time average of <w_p> (Eq. 29).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/run_status.hpp"
#include "particles/dem_system.hpp"
#include "scenes/particle_setup.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"
#include "stats/running.hpp"

namespace boycott::scenes {

namespace {

/// The particles of the case in a dry engine (no fluid arrays in the kicks), with the Stokes drag
/// against still fluid as the implicit beta toward rest where asked.
void set_up_particles(particles::DemSystem& dem, const CaseParams& p, ModelTimers& timers) {
  insert_case_particles(dem, p);
  auto& s = dem.particles();
  const bool stokes = p.forces.drag == "stokes";
  if (stokes) {
    const double beta = 3.0 * kPi * p.fluid.viscosity_pa_s * p.particles.diameter_m;  // kg/s
    for (std::size_t i = 0; i < s.n_local; ++i) s.beta[i] = beta;
  }
  dem.initialize();
  particles::activate_dem_models(timers, p);
  timers.activate("integration", "velocity Verlet");
  if (stokes) timers.activate("stokes_drag", "implicit in the velocity update (timed with integration)");
}

/// The mean of a particle array over this process's particles (0 without any).
double mean_over_particles(const particles::ParticleStore& s, const std::vector<double>& a) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) sum += a[i];
  return s.n_local > 0 ? sum / static_cast<double>(s.n_local) : 0.0;
}

/// The summary: the common keys and the engine's record at the end.
nlohmann::json dem_summary(const CaseParams& p, const particles::DemSystem& dem, SummaryBase& sb,
                           const stats::BatchMeans& wp_avg, const ModelTimers& timers) {
  const auto& s = dem.particles();
  sb.particle_steps = static_cast<double>(s.n_local) * static_cast<double>(dem.steps());
  sb.mean_settling_velocity_m_s = wp_avg.count() ? wp_avg.mean() : kUnset;
  sb.settling_velocity_stderr_m_s = wp_avg.stderr_of_mean();
  auto j = make_summary(p, sb, timers);
  j["particle_count"] = s.n_local;
  j["solid_fraction"] = p.solid_fraction();
  j["dem_steps"] = dem.steps();
  j["neighbor_rebuilds"] = dem.rebuilds();
  j["contacts_final"] = dem.contact_count();
  j["kinetic_energy_final_j"] = dem.kinetic_energy_j();
  const double dem_seconds = dem.seconds_force + dem.seconds_neighbor + dem.seconds_integrate;
  j["ns_per_particle_step"] = sb.particle_steps > 0 ? dem_seconds / sb.particle_steps * 1e9 : 0.0;
  if (p.forces.drag == "stokes") {
    // Terminal velocity of a lone particle under this drag (no buoyancy: still fluid only drags).
    const double g_along_z = p.gravity_vector()[2];
    j["stokes_terminal_velocity_z_m_s"] =
        p.particle_mass_kg() * g_along_z / (3.0 * kPi * p.fluid.viscosity_pa_s * p.particles.diameter_m);
  }
  return j;
}

}  // namespace

int run_dem_only(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  auto dc = particles::DemConfig::from_case(p);
  dc.dry = true;
  particles::DemSystem dem(dc);
  set_up_particles(dem, p, timers);
  const auto& s = dem.particles();
  const double dt = p.time.dt_dem_s;
  const auto nsteps = static_cast<std::int64_t>(std::llround(p.time.end_s / dt));
  const double out_every =
      is_set(p.output.timeseries_every_s) ? p.output.timeseries_every_s : p.time.dt_cfd_s;
  const auto out_stride = std::max<std::int64_t>(1, std::llround(out_every / dt));
  const auto avg_from_step = static_cast<std::int64_t>(std::llround(p.time.average_from.time_s / dt));
  CsvWriter csv(ctx.out_dir / "timeseries.csv",
                {"time_s", "mean_vx_m_s", "mean_vy_m_s", "mean_vz_m_s", "kinetic_energy_j", "contacts",
                 "neighbor_rebuilds"},
                false);
  stats::BatchMeans wp_avg;
  const double N = static_cast<double>(s.n_local);
  SummaryBase sb;
  int exit_code = kExitOk;
  // The steps run in chunks that end at each output step and where the average starts, so that
  // DemSystem::advance fuses the kicks between the steps of a chunk; it returns each step's sum
  // of v_z (the same bits as the mean of s.vz after every step). Chunks of at most kChunk steps
  // keep a stop request answered within a fraction of a second.
  constexpr std::int64_t kChunk = 200;
  std::vector<double> vz_sums;
  for (std::int64_t n = 0; n < nsteps;) {
    std::int64_t stop = std::min({nsteps, (n / out_stride + 1) * out_stride, n + kChunk});
    if (n < avg_from_step) stop = std::min(stop, avg_from_step);
    const bool averaging = n >= avg_from_step;  // step n + 1 is past the average's start
    vz_sums.resize(static_cast<std::size_t>(stop - n));
    dem.advance(static_cast<int>(stop - n), averaging ? vz_sums.data() : nullptr);
    if (averaging)
      for (double sum : vz_sums) wp_avg.add(N > 0 ? sum / N : 0.0);
    n = stop;
    if (n % out_stride == 0 || n == nsteps) {
      const double ke = dem.kinetic_energy_j();
      if (!std::isfinite(ke))
        throw PhysicsError(
            fmt::format("non-finite particle kinetic energy at t = {} s (step {})", dem.time_s(), n));
      csv.row({dem.time_s(), mean_over_particles(s, s.vx), mean_over_particles(s, s.vy),
               mean_over_particles(s, s.vz), ke, static_cast<double>(dem.contact_count()),
               static_cast<double>(dem.rebuilds())});
      if (ctx.progress) ctx.progress(dem.time_s());
    }
    if (ctx.should_stop()) {
      // Exit 75 as every scene's stop (a study runs it again, not counting a failure), but no
      // checkpoint is written by this scene yet: say so instead of claiming a resumable stop.
      sb.status = kStatusInterrupted;
      exit_code = kExitInterrupted;
      std::fprintf(stderr,
                   "interrupted at t = %g s; dem_only writes no checkpoint yet, a rerun starts over\n",
                   dem.time_s());
      break;
    }
  }
  csv.flush();
  timers.add("dem_contacts", dem.seconds_force);
  timers.add("neighbor_search", dem.seconds_neighbor);
  timers.add("integration", dem.seconds_integrate);
  sb.simulated_time_s = dem.time_s();
  sb.set_spent(clock.spent());
  const auto j = dem_summary(p, dem, sb, wp_avg, timers);
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return exit_code;
}

namespace {

/// No fluid: a drag against still fluid (Stokes) or none.
void dem_only_checks(const CaseParams& p, SceneFindings& f) {
  if (p.forces.drag != "none" && p.forces.drag != "stokes")
    f.errors.push_back(
        fmt::format("forces.drag = \"{}\": the dem_only scene has no fluid; use \"stokes\" (drag "
                    "against still fluid) or \"none\"",
                    p.forces.drag));
}

}  // namespace

const SceneRegistration kRegistered{
    {.name = "dem_only",
     .measures = "particles alone (optionally a Stokes drag against still fluid): <<w_p>>, contacts, speed",
     .reads = {"seed", "particles.", "contact.", "domain.length_x", "domain.width_y", "domain.height_z",
               "domain.periodic_y", "gravity.", "time.dt_dem", "time.dt_cfd", "time.end", "time.average_from",
               "forces.drag", "fluid.viscosity", "numerics.neighbor_skin", "output.timeseries_every"},
     .defaults = {{"forces.drag", "\"none\""}},
     .default_solid_fraction = table3_solid_fraction(),
     .has_fluid = false,
     .own_checks = &dem_only_checks},
    &run_dem_only};

}  // namespace boycott::scenes
