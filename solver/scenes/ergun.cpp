// Scene ergun (paper section III A, Table I): a DEM-packed bed in a fully periodic box, then the
// particles are frozen and the fluid is driven through it by a swept mean pressure gradient
// (ergun.pressure_gradients, Pa/m). For each gradient the coupled solver runs to a steady state;
// the superficial velocity U = <alpha_f w> is measured from the fluid velocity field and compared
// through f* (Eq. 21) against Re*_p (Eq. 22) with the Ergun equation (Eq. 20).
//
// Left out: DEM contacts after packing (the bed is frozen), gravity (the driving gradient is the
// only force, as in the paper), Saffman lift and added mass (steady flow through a fixed bed; set
// them on in [forces] to include them anyway).
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "coupling/coupled_system.hpp"
#include "scenes/particle_setup.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {

namespace {

/// Steps the frozen-bed flow until U changes by less than `tol` relative per step (at least
/// `min_steps`, at most `max_steps`). Returns the number of steps.
int run_to_steady(coupling::CoupledSystem& run, double tol, int min_steps, int max_steps,
                  const RunContext& ctx) {
  double u_old = run.fluid().mean_flux_z();
  for (int k = 1; k <= max_steps; ++k) {
    run.step();
    const double u = run.fluid().mean_flux_z();
    if (!std::isfinite(u))
      throw PhysicsError(fmt::format("ergun: superficial velocity became NaN at step {}", k));
    if (k >= min_steps && std::abs(u - u_old) <= tol * std::abs(u)) return k;
    u_old = u;
    if (ctx.should_stop()) return -k;
  }
  return max_steps;
}

}  // namespace

int run_ergun(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  CaseParams q = p;
  q.gravity.magnitude_m_s2 = 0.0;
  coupling::CoupledSystem run(q, coupling::CoupledOptions{false, false});
  {
    ModelTimers::Scope pack(timers, "packing");
    insert_case_particles(run.dem(), q);
  }
  timers.activate("packing", fmt::format("DEM, insertion \"{}\"", p.particles.insertion));
  run.start();
  run.activate_models(timers);
  run.fluid().set_target_mean_flux_z(kUnset);

  const double vbox = p.box_volume_m3();
  const double porosity = 1.0 - run.coupler().totals().solid_volume_m3 / vbox;
  const double d = p.particles.diameter_m, rho = p.fluid.density_kg_m3, mu = p.fluid.viscosity_pa_s;
  CsvWriter csv(ctx.out_dir / "timeseries.csv",
                {"point", "pressure_gradient_pa_m", "superficial_velocity_m_s", "steps", "re_star", "f_star",
                 "f_star_ergun"},
                false);
  nlohmann::json points = nlohmann::json::array();
  double max_err = 0.0;
  int exit_code = kExitOk;
  SummaryBase sb;
  int idx = 0;
  for (double dpdl : p.ergun.pressure_gradients_pa_m) {
    // Flow in +z: the driving gradient is negative (the fluid equation carries -alpha_f G).
    run.fluid().set_mean_pressure_gradient_pa_m(-dpdl);
    const int steps = run_to_steady(run, 1e-7, 20, 20000, ctx);
    if (steps < 0) {
      sb.status = kStatusInterrupted;
      // Exit 75 as every scene's stop, not a failure a study would count against its retries.
      exit_code = kExitInterrupted;
      std::fprintf(stderr, "interrupted; ergun writes no checkpoint, a rerun starts over\n");
      break;
    }
    const double U = run.fluid().mean_flux_z();
    const double ap = 1.0 - porosity;
    const double re = rho * d * U / (mu * ap);
    const double fs = dpdl * d / (rho * U * U) * porosity * porosity * porosity / ap;
    const double fe = 150.0 / re + 1.75;
    const double err = (fs - fe) / fe;
    max_err = std::max(max_err, std::abs(err));
    points.push_back({{"re_star", re},
                      {"f_star", fs},
                      {"f_star_ergun", fe},
                      {"rel_error", err},
                      {"superficial_velocity_m_s", U},
                      {"pressure_gradient_pa_m", dpdl},
                      {"porosity", porosity},
                      {"steps_to_steady", steps}});
    csv.row({static_cast<double>(idx++), dpdl, U, static_cast<double>(steps), re, fs, fe});
    if (ctx.progress) ctx.progress(run.time_s());
  }
  csv.flush();
  run.report_timers(timers);
  sb.simulated_time_s = run.time_s();
  sb.set_spent(clock.spent());
  sb.particle_steps = 0.0;
  auto j = make_summary(p, sb, timers);
  j["ranks"] = run.rank_report();
  j["points"] = points;
  j["max_rel_error_f_star"] = max_err;
  j["porosity"] = porosity;
  j["particle_count"] = run.dem().global_count();
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return exit_code;
}

const SceneRegistration kRegistered{
    {.name = "ergun",
     .measures = "f* against Re*_p through a packed, frozen bed, beside the Ergun equation",
     .reads = {"seed", "fluid.", "particles.", "contact.", "domain.", "time.dt_cfd", "time.dt_dem", "forces.",
               "numerics.", "ergun."},
     .defaults = {{"domain.periodic_y", "true"},
                  {"particles.insertion", "\"packed\""},
                  {"fluid.subgrid_model", "\"none\""},
                  {"forces.saffman_lift", "false"},
                  {"forces.added_mass", "false"}},
     .default_solid_fraction = 0.64,
     .particles_move = false,
     .tolerances = {{"max_rel_error_f_star", 0.005, "the Ergun equation (the paper's 0.5 %)"}}},
    &run_ergun};

}  // namespace boycott::scenes
