// Scene single_particle: one sphere released from rest at the centre of the box, settling under
// the same forcing as inclined_settling (z periodic, G holding the slurry velocity at zero, which
// for one particle is ordinary buoyancy) with two-way coupling on: the fluid is solved and feels
// the particle. Measures the terminal velocity against the isolated value of the drag law
// (alpha_f = 1 in Eq. 13) and the start-up acceleration against (rho_p - rho_f) g / (rho_p + C rho_f)
// (C = 1/2 with added mass, 0 without).
//
// An unresolved particle drags the fluid at its own position through its own momentum source;
// on cells only a few diameters wide that biases the slip velocity. This scene does not correct
// for it: keep cells several diameters wide (the summary reports dx/d and the test shows how the
// error falls as dx/d grows).
//
// It runs the coupled scenes' time loop (scenes/coupled_output.hpp): rows every
// output.timeseries_every (every step when unset), checkpoints, pictures, and a stop that
// checkpoints and resumes.
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/run_status.hpp"
#include "coupling/coupled_system.hpp"
#include "coupling/drag_laws.hpp"
#include "io/checkpoint_file.hpp"
#include "io/state_io.hpp"
#include "scenes/coupled_checkpoint.hpp"
#include "scenes/coupled_output.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"
#include "stats/running.hpp"

namespace boycott::scenes {

namespace {

/// The isolated terminal velocity from the case's drag law, m/s (unset without drag: there is
/// none).
double terminal_speed_m_s(const CaseParams& p) {
  return p.forces.drag == "none" ? kUnset : coupling::visit_drag_law(p.forces.drag, [&](const auto& law) {
    return coupling::terminal_slip_speed(law, 1.0, p.particles.diameter_m, p.particles.density_kg_m3,
                                         p.fluid.density_kg_m3, p.fluid.viscosity_pa_s,
                                         p.gravity.magnitude_m_s2);
  });
}

/// The summary keys that compare the run with an isolated sphere in an unbounded fluid: the
/// terminal velocity along g, the initial acceleration from rest, the Stokes response time.
void report_against_isolated_sphere(nlohmann::json& j, const CaseParams& p, double wt, double acc0) {
  const double vt = terminal_speed_m_s(p);
  const auto g = p.gravity_vector();
  const double gmag = p.gravity.magnitude_m_s2;
  const double ref_wz = gmag > 0 ? vt * g[2] / gmag : kUnset;  // settles along g in an unbounded fluid
  const double rp = p.particles.density_kg_m3, rf = p.fluid.density_kg_m3;
  const double cam = p.forces.added_mass ? 0.5 : 0.0;
  const double acc_ref = (p.forces.pressure_gradient ? (rp - rf) : rp) * g[2] / (rp + cam * rf);
  const double d = p.particles.diameter_m, nu = p.fluid.viscosity_pa_s / rf;
  j["terminal_velocity_m_s"] = wt;
  j["terminal_velocity_reference_m_s"] = ref_wz;
  j["rel_error"] = is_set(ref_wz) && ref_wz != 0.0 ? (wt - ref_wz) / ref_wz : kUnset;
  j["reynolds_number_reference"] = vt * d / nu;
  j["cell_size_over_diameter"] = p.domain.length_x_m / static_cast<double>(p.domain.cells[0]) / d;
  j["initial_acceleration_z_m_s2"] = acc0;
  j["initial_acceleration_reference_z_m_s2"] = acc_ref;
  j["response_time_s"] = rp * d * d / (18.0 * p.fluid.viscosity_pa_s);
  j["dt_dem_over_response_time"] = p.time.dt_dem_s / (rp * d * d / (18.0 * p.fluid.viscosity_pa_s));
}

}  // namespace

int run_single_particle(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true});
  const auto& s = run.dem().particles();
  stats::BatchMeans wp_avg;
  double acc0 = kUnset, next_out = 0.0;  // next_out: the resumed output's, s

  const auto resumed = resume_coupled(
      run, ctx.out_dir, ctx.quiet,
      [&](const io::CheckpointReader& r) {
        io::load(r, "stats.wp.", wp_avg);
        acc0 = r.scalar("stats.initial_acceleration");
        next_out = r.scalar("stats.next_out");
      },
      ctx.branch_checkpoint);
  if (resumed) {
    carry_spent(*resumed, clock, timers);
  } else {
    const auto& box = run.dem().config().box;
    run.dem().add_particle(0, box.lo[0] + 0.5 * box.len[0], box.lo[1] + 0.5 * box.len[1],
                           box.lo[2] + 0.5 * box.len[2], 0.5 * p.particles.diameter_m,
                           p.particles.density_kg_m3);
    run.start();
  }
  run.activate_models(timers);
  run.set_interrupt([&ctx] { return ctx.should_stop(); });
  const double d = p.particles.diameter_m, nu = p.fluid.viscosity_pa_s / p.fluid.density_kg_m3;

  CoupledSceneOutput out(run, ctx, timers,
                         {"time_s", "wp_m_s", "up_m_s", "vp_m_s", "mean_wf_m_s", "slurry_velocity_m_s",
                          "driving_gradient_pa_m", "reynolds_number"},
                         resumed.has_value(), next_out);
  auto write_checkpoint = [&] {
    ModelTimers::Scope sc(timers, "checkpoints");
    checkpoint_coupled(run, ctx.out_dir, spent_so_far(clock, timers, run), [&](io::CheckpointWriter& w) {
      io::save(w, "stats.wp.", wp_avg);
      w.put("stats.initial_acceleration", acc0);
      w.put("stats.next_out", out.next_out_s());
    });
  };
  // The particle lives on one rank: its values as every rank sees them (collective).
  const auto particle = [&](const std::vector<double>& a) { return run.global_sum(s.n_local ? a[0] : 0.0); };
  const auto measure = [&](const coupling::CoupledStep& st, bool&) {
    const double t = run.time_s();
    const double vx = particle(s.vx), vy = particle(s.vy), vz = particle(s.vz);
    if (run.steps() == 1) acc0 = vz / st.dt_s;
    if (t > p.time.average_from.time_s + 1e-12) wp_avg.add(vz);
    const double slip = std::sqrt(std::pow(vx - particle(s.ufx), 2) + std::pow(vy - particle(s.ufy), 2) +
                                  std::pow(vz - particle(s.ufz), 2));
    return [&run, t, vx, vy, vz, re = slip * d / nu]() -> std::vector<double> {
      return {t,
              vz,
              vx,
              vy,
              run.mean_fluid_velocity_z(),
              run.slurry_velocity_z(),
              run.fluid().mean_pressure_gradient_pa_m(),
              re};
    };
  };
  SummaryBase sb;
  const int exit_code = run_coupled_steps(
      run, out, [] {}, measure, write_checkpoint, sb);
  out.flush();
  run.report_timers(timers);

  const double wt = wp_avg.count() ? wp_avg.mean() : particle(s.vz);
  sb.simulated_time_s = run.time_s();
  sb.set_spent(clock.spent());
  sb.particle_steps = static_cast<double>(run.dem().steps());
  sb.mean_settling_velocity_m_s = wt;
  sb.settling_velocity_stderr_m_s = wp_avg.stderr_of_mean();
  auto j = make_summary(p, sb, timers);
  j["ranks"] = run.rank_report();
  report_against_isolated_sphere(j, p, wt, acc0);
  j["resumed_from_checkpoint"] = resumed.has_value();
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return exit_code;
}

const SceneRegistration kRegistered{
    {.name = "single_particle",
     .measures = "terminal velocity of one sphere against the drag law's",
     .reads = {"fluid.", "particles.diameter", "particles.density", "contact.", "domain.", "gravity.",
               "time.dt_cfd", "time.dt_dem", "time.end", "time.average_from", "time.checkpoint_every",
               "forces.", "numerics.", "output.timeseries_every", "output.keep_checkpoints",
               "output.snapshot_times", "output.image_times"},
     .has_particles = false,
     .fixed_particle_count = 1,
     .tolerances = {{"rel_error", 0.02, "the drag law's isolated terminal velocity"}}},
    &run_single_particle};

}  // namespace boycott::scenes
