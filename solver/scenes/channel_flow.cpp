// Scene `channel_flow`: the fluid solver alone between the y walls (or fully periodic), driven
// by `[flow] body_acceleration` and, when `target_mean_velocity_z` is set, by the flux
// controller's mean pressure gradient. Gravity is not applied: in a periodic column it would be
// balanced by the hydrostatic gradient, so a scene that wants a driving force says so in [flow].
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "core/timers.hpp"
#include "fluid/fluid_solver.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {

namespace {

/// Steady analytic streamwise profile w(y) (m/s) where one exists, else an empty function:
///  * flux controller on, no-slip walls: w = 6 U y (W - y) / W^2 (any body force is absorbed by G);
///  * body force g_z only, no-slip walls: plane Poiseuille w = g_z y (W - y) / (2 nu);
///  * slip top wall: the half channel w = g_z y (2W - y) / (2 nu), or 3 U y (2W - y) / (2 W^2).
std::function<double(double)> analytic_profile(const CaseParams& p) {
  if (p.domain.periodic_y) return {};
  const auto& g = p.flow.body_acceleration_m_s2;
  if (g[0] != 0.0 || g[1] != 0.0) return {};
  const double W = p.domain.width_y_m;
  const double nu = p.fluid.viscosity_pa_s / p.fluid.density_kg_m3;
  const bool slip = p.domain.top_wall == "slip";
  // Vreman's viscosity vanishes in plane shear, so the laminar profile holds with it on too.
  if (is_set(p.flow.target_mean_velocity_z_m_s)) {
    const double U = p.flow.target_mean_velocity_z_m_s;
    if (slip) return [=](double y) { return 1.5 * U * y * (2.0 * W - y) / (W * W); };
    return [=](double y) { return 6.0 * U * y * (W - y) / (W * W); };
  }
  if (g[2] == 0.0) return {};
  if (slip) return [=](double y) { return g[2] * y * (2.0 * W - y) / (2.0 * nu); };
  return [=](double y) { return g[2] * y * (W - y) / (2.0 * nu); };
}

/// Streamwise velocity at y = W/2 (no-slip) from the x-z averaged profile, linear between cells.
double centreline(const std::vector<double>& w, double W, bool slip) {
  const int ny = static_cast<int>(w.size());
  const double y = slip ? W : 0.5 * W;  // the slip wall is the symmetry plane of the half channel
  const double h = W / ny;
  const double s = std::clamp(y / h - 0.5, 0.0, ny - 1.0);
  const int j = std::min(static_cast<int>(s), ny - 2);
  const double f = s - j;
  return (1.0 - f) * w[j] + f * w[j + 1];
}

/// One row of timeseries.csv. mean_velocity() is collective: every rank evaluates the row, rank
/// 0 writes it.
std::vector<double> channel_row(fluid::FluidSolver& solver, const CaseParams& p, bool top_slip, double dt,
                                const fluid::StepReport& rep) {
  const auto w = solver.profile_y(2);
  const double wc =
      p.domain.periodic_y ? solver.mean_velocity(2) : centreline(w, p.domain.width_y_m, top_slip);
  return {solver.time_s(),
          dt,
          solver.mean_velocity(0),
          solver.mean_velocity(1),
          solver.mean_velocity(2),
          wc,
          rep.mean_pressure_gradient_pa_m,
          (double)rep.simple_iterations,
          (double)rep.pressure_krylov_iterations,
          rep.continuity_residual};
}

/// The summary keys of the flow at the end, and its largest deviation from the analytic profile
/// where there is one (relative to the profile's largest speed).
void report_flow(nlohmann::json& j, fluid::FluidSolver& solver, const CaseParams& p, bool top_slip) {
  const auto w = solver.profile_y(2);
  j["mean_velocity_m_s"] = solver.mean_velocity(2);
  j["mean_velocity_vector_m_s"] = {solver.mean_velocity(0), solver.mean_velocity(1), solver.mean_velocity(2)};
  j["mean_flux_z_m_s"] = solver.mean_flux_z();
  j["centerline_velocity_m_s"] = p.domain.periodic_y
                                     ? nlohmann::json(nullptr)
                                     : nlohmann::json(centreline(w, p.domain.width_y_m, top_slip));
  j["mean_pressure_gradient_pa_m"] = solver.mean_pressure_gradient_pa_m();
  j["cfd_steps"] = solver.steps_done();
  const auto exact = analytic_profile(p);
  if (!exact) {
    j["max_rel_error_vs_analytic"] = nullptr;
    return;
  }
  const int ny = static_cast<int>(w.size());
  const double h = p.domain.width_y_m / ny;
  double emax = 0.0, ref = 0.0;
  for (int jy = 0; jy < ny; ++jy) ref = std::max(ref, std::abs(exact((jy + 0.5) * h)));
  ref = std::max(ref, std::abs(exact(top_slip ? p.domain.width_y_m : 0.5 * p.domain.width_y_m)));
  for (int jy = 0; jy < ny; ++jy) emax = std::max(emax, std::abs(w[jy] - exact((jy + 0.5) * h)));
  j["max_rel_error_vs_analytic"] = ref > 0.0 ? nlohmann::json(emax / ref) : nlohmann::json(nullptr);
  j["analytic_centerline_velocity_m_s"] = exact(top_slip ? p.domain.width_y_m : 0.5 * p.domain.width_y_m);
}

}  // namespace

int run_channel_flow(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  const auto settings = fluid::FluidSettings::from_case(p);
  timers.activate("fluid", "staggered FV, QUICK, BDF2, " + settings.coupling_name());
  if (settings.vreman) timers.activate("subgrid_viscosity", "vreman");
  if (std::isfinite(settings.target_mean_flux_z_m_s))
    timers.activate("flux_controller", "mean pressure gradient z");

  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const bool io = rank == 0;

  fluid::FluidSolver solver(settings);
  std::unique_ptr<CsvWriter> csv;
  if (io)
    csv = std::make_unique<CsvWriter>(
        ctx.out_dir / "timeseries.csv",
        std::vector<std::string>{"time_s", "dt_s", "mean_velocity_x_m_s", "mean_velocity_y_m_s",
                                 "mean_velocity_z_m_s", "centerline_velocity_m_s",
                                 "mean_pressure_gradient_pa_m", "simple_iterations",
                                 "pressure_krylov_iterations", "continuity_residual"},
        false);

  const double end = p.time.end_s;
  const double every = is_set(p.output.timeseries_every_s) ? p.output.timeseries_every_s : 0.0;
  double next_row = 0.0;
  bool interrupted = false;
  int unconverged = 0;
  while (!reached_end(solver.time_s(), end)) {
    if (ctx.should_stop()) {
      interrupted = true;
      break;
    }
    double dt = solver.stable_dt();
    dt = std::min(dt, end - solver.time_s());
    fluid::StepReport rep;
    {
      ModelTimers::Scope t(timers, "fluid");
      rep = solver.step(dt);
    }
    if (!rep.converged) ++unconverged;
    if (solver.time_s() >= next_row - 1e-12 || reached_end(solver.time_s(), end)) {
      const std::vector<double> row = channel_row(solver, p, settings.top_slip, dt, rep);
      if (csv) csv->row(row);
      next_row = solver.time_s() + every;
    }
    if (ctx.progress) ctx.progress(solver.time_s());
  }
  if (csv) csv->flush();

  SummaryBase base;
  base.status = interrupted ? kStatusInterrupted : kStatusCompleted;
  base.simulated_time_s = solver.time_s();
  base.set_spent(clock.spent());
  nlohmann::json j = make_summary(p, base, timers);
  report_flow(j, solver, p, settings.top_slip);
  j["unconverged_steps"] = unconverged;
  if (io) write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  if (!ctx.quiet && io)
    std::printf(
        "channel_flow: t = %.4g s, %d steps, mean w %.6g m/s, centreline %.6g m/s, error vs analytic %s\n",
        solver.time_s(), solver.steps_done(), j["mean_velocity_m_s"].get<double>(),
        j["centerline_velocity_m_s"].is_null() ? 0.0 : j["centerline_velocity_m_s"].get<double>(),
        j["max_rel_error_vs_analytic"].dump().c_str());
  return interrupted ? kExitInterrupted : kExitOk;
}

const SceneRegistration kRegistered{
    {.name = "channel_flow",
     .measures = "fluid alone: mean and centreline velocity against plane Poiseuille",
     .reads = {"fluid.", "domain.", "time.dt_cfd", "time.end", "flow.", "numerics.simple_max_iterations",
               "numerics.simple_tolerance", "numerics.velocity_relaxation", "numerics.pressure_relaxation",
               "numerics.pressure_velocity_coupling", "numerics.piso_correctors",
               "numerics.simple_correctors", "numerics.cfl_max", "output.timeseries_every"},
     .defaults = {{"fluid.subgrid_model", "\"none\""}},
     .has_particles = false},
    &run_channel_flow};

}  // namespace boycott::scenes
