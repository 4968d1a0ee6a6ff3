// Scene inclined_settling (paper sections IV-V, Table III): a suspension settling in a narrow
// channel inclined at theta, periodic in x and z, walls at y = 0 and W, the slurry velocity held
// at zero by the driving gradient G (Eq. 25). Measures <w_p>(t) and <w_f>(t) (Eq. 28), the
// ensemble average <<w_p>> over [average_from, end] with its error from the autocorrelation of the
// whole <w_p> series over the window (stats/window_error.hpp, scenes/summary_statistics.hpp;
// Eq. 29), and the PDFs of particle y and w_p over the same window (Fig. 12). With
// time.target_rel_error it stops once <<w_p>> is that precise (status converged).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "coupling/drag_laws.hpp"
#include "io/checkpoint_file.hpp"
#include "io/state_io.hpp"
#include "scenes/coupled_checkpoint.hpp"
#include "scenes/coupled_output.hpp"
#include "scenes/particle_setup.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scenes_list.hpp"
#include "scenes/summarize.hpp"
#include "scenes/summary_statistics.hpp"
#include "stats/precision_target.hpp"
#include "stats/running.hpp"
#include "stats/transient.hpp"
#include "stats/window_error.hpp"

namespace boycott::scenes {

namespace {

// Richardson & Zaki (1954) with the Garside & Al-Dibouni (1977) exponent, as Di Felice (1994)
// quotes it: n = (5.1 + 0.27 Re_t^0.9) / (1 + 0.1 Re_t^0.9), Re_t = rho_f w_t d / mu. Settling speed of a
// homogeneous suspension relative to zero volume flux, w_t (1 - alpha_p)^n.
double richardson_zaki_speed(double wt, double re_t, double alpha_p) {
  const double r = std::pow(re_t, 0.9);
  const double n = (5.1 + 0.27 * r) / (1.0 + 0.1 * r);
  return wt * std::pow(1.0 - alpha_p, n);
}

double isolated_terminal_speed(const CaseParams& p) {
  return coupling::visit_drag_law(p.forces.drag, [&](const auto& law) {
    return coupling::terminal_slip_speed(law, 1.0, p.particles.diameter_m, p.particles.density_kg_m3,
                                         p.fluid.density_kg_m3, p.fluid.viscosity_pa_s,
                                         p.gravity.magnitude_m_s2);
  });
}

/// A histogram of the particles of every rank (each rank counts its own).
stats::Histogram over_ranks(const coupling::CoupledSystem& run, stats::Histogram h) {
  for (double& c : h.counts_) c = run.global_sum(c);
  h.outside_ = run.global_sum(h.outside_);
  h.total_ = run.global_sum(h.total_);
  return h;
}

void write_pdf(const std::filesystem::path& path, const std::string& column, const stats::Histogram& h) {
  std::string text = fmt::format("{},probability_density\n", column);
  const auto dens = h.density();
  for (int b = 0; b < h.bins(); ++b) text += fmt::format("{:.9g},{:.9g}\n", h.bin_center(b), dens[b]);
  write_file_atomic(path, text);
}

}  // namespace

int run_inclined_settling(const CaseParams& p, RunContext& ctx) {
  WallClock clock;
  ModelTimers timers;
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true});
  const auto& s = run.dem().particles();
  const double vt = isolated_terminal_speed(p);
  const double W = p.domain.width_y_m;
  const int bins = static_cast<int>(p.output.pdf_bins);
  stats::Histogram pdf_y(0.0, W, bins);
  // w_p range: a few isolated terminal speeds either way (values outside are counted apart).
  const double wrange = std::max(8.0 * vt, 0.05);
  stats::Histogram pdf_w(-wrange, 0.5 * wrange, bins);
  // The transverse force budget over the same window and bands as pdf_y (output.force_budget_y).
  std::optional<coupling::ForceBudget> budget;
  if (p.output.force_budget_y) budget.emplace(run.dem().config().box.lo[1], W, bins);
  stats::BatchMeans wp_avg, wf_avg, slurry_avg;
  // Every <w_p> sample of the window, for its error (20 s of 1 ms steps: 15 000 doubles).
  std::vector<double> wp_series;
  bool wp_series_whole = true;  // false after resuming a checkpoint of a build that kept none
  // The samples before the window (the transient's detection) and the step lengths (s) of all.
  stats::StepSeries steps;
  stats::PrecisionTarget target(p.time.target_rel_error, p.time.average_from.automatic);
  // With time.average_from = "auto" every step is collected and the window is cut at the end,
  // where the series shows its start-up transient over (the PDFs and fluid means keep all of it).
  const double collect_from_s = p.time.average_from.collect_from_s();
  double slurry_max = 0.0, next_out = 0.0, wall_before = 0.0;  // next_out: the resumed output's, s
  // Stability record over the whole run (issue 7): alpha_f range and the largest kinetic energy.
  double alpha_min_seen = 1.0, alpha_max_seen = 0.0, ke_max_seen = 0.0;

  // Resume from the newest checkpoint, or start.
  const auto resumed = resume_coupled(
      run, ctx.out_dir, ctx.quiet,
      [&](const io::CheckpointReader& r) {
        io::load(r, "stats.wp.", wp_avg);
        io::load(r, "stats.wf.", wf_avg);
        io::load(r, "stats.slurry.", slurry_avg);
        // The histograms are counts over all ranks: rank 0 carries them on, the others add theirs.
        if (output_rank()) {
          io::load(r, "stats.pdf_y.", pdf_y);
          io::load(r, "stats.pdf_w.", pdf_w);
          // A run that was not recording its budget has none to carry on (it starts now).
          if (budget && r.has("stats.budget.0.counts")) {
            const auto h = budget->all();
            for (std::size_t k = 0; k < h.size(); ++k) io::load(r, fmt::format("stats.budget.{}.", k), *h[k]);
          }
        }
        slurry_max = r.scalar("stats.slurry_max");
        next_out = r.scalar("stats.next_out");
        if (r.has("stats.alpha_min_seen")) {  // absent in checkpoints of earlier builds
          alpha_min_seen = r.scalar("stats.alpha_min_seen");
          alpha_max_seen = r.scalar("stats.alpha_max_seen");
          ke_max_seen = r.scalar("stats.ke_max_seen");
        }
        steps = read_step_series(r);
        if (r.has("stats.wp_series")) {
          wp_series = r.doubles("stats.wp_series");
          const auto t = r.doubles("stats.target");
          if (t.size() == 2) target.next_check_ = static_cast<std::int64_t>(t[0]), target.met_since_s_ = t[1];
        } else {
          wp_series_whole = wp_avg.count() == 0;
        }
      },
      ctx.branch_checkpoint);
  if (resumed) {
    wall_before = *resumed;
  } else {
    insert_case_particles(run.dem(), p);
    run.start();
  }
  run.activate_models(timers);
  // A stop request is honoured inside a long fluid step too (thousands of particle sub-steps).
  run.set_interrupt([&ctx] { return ctx.should_stop(); });
  CoupledSceneOutput out(
      run, ctx, timers,
      {"time_s", "mean_wp_m_s", "mean_wf_m_s", "slurry_velocity_m_s", "mean_up_m_s", "mean_vp_m_s",
       "driving_gradient_pa_m", "dt_s", "simple_iterations", "min_alpha_f", "kinetic_energy_j"},
      resumed.has_value(), next_out);
  auto write_checkpoint = [&] {
    ModelTimers::Scope sc(timers, "checkpoints");
    // Everything summed over ranks is summed here, on every rank: the writer below runs on rank 0
    // alone, and a collective inside it would wait for ranks that never enter it.
    const stats::Histogram all_y = over_ranks(run, pdf_y), all_w = over_ranks(run, pdf_w);
    std::vector<stats::Histogram> all_budget;
    if (budget)
      for (const stats::Histogram* h : budget->all()) all_budget.push_back(over_ranks(run, *h));
    checkpoint_coupled(run, ctx.out_dir, wall_before + clock.seconds(), [&](io::CheckpointWriter& w) {
      io::save(w, "stats.wp.", wp_avg);
      io::save(w, "stats.wf.", wf_avg);
      io::save(w, "stats.slurry.", slurry_avg);
      io::save(w, "stats.pdf_y.", all_y);
      io::save(w, "stats.pdf_w.", all_w);
      for (std::size_t k = 0; k < all_budget.size(); ++k)
        io::save(w, fmt::format("stats.budget.{}.", k), all_budget[k]);
      w.put("stats.slurry_max", slurry_max);
      w.put("stats.next_out", out.next_out_s());
      w.put("stats.alpha_min_seen", alpha_min_seen);
      w.put("stats.alpha_max_seen", alpha_max_seen);
      w.put("stats.ke_max_seen", ke_max_seen);
      w.put("stats.wp_series", wp_series);
      write_step_series(w, steps);
      w.put("stats.target",
            std::vector<double>{static_cast<double>(target.next_check_), target.met_since_s_});
    });
  };
  SummaryBase sb;
  const double end = p.time.end_s;
  const auto before_step = [&] {
    if (budget) run.set_force_budget(run.time_s() >= collect_from_s - 1e-12 ? &*budget : nullptr);
  };
  const auto measure = [&](const coupling::CoupledStep& st, bool& end_early) {
    const double t = run.time_s();
    const double wp = run.mean_particle_velocity(2);
    const double wf = run.mean_fluid_velocity_z();
    const double slurry = run.slurry_velocity_z();
    alpha_min_seen = std::min(alpha_min_seen, run.coupler().totals().min_alpha_f);
    alpha_max_seen = std::max(alpha_max_seen, run.coupler().totals().max_alpha_f);
    ke_max_seen = std::max(ke_max_seen, run.dem().kinetic_energy_j());
    if (t > collect_from_s + 1e-12) {
      wp_avg.add(wp);
      wp_series.push_back(wp);
      steps.window_dt.push_back(st.dt_s);
      wf_avg.add(wf);
      slurry_avg.add(slurry);
      slurry_max = std::max(slurry_max, std::abs(slurry));
      for (std::size_t i = 0; i < s.n_local; ++i) {
        pdf_y.add(s.y[i]);
        pdf_w.add(s.vz[i]);
      }
    } else {
      steps.before.push_back(wp);
      steps.before_dt.push_back(st.dt_s);
    }
    // time.target_rel_error met before time.end: the last row, a checkpoint, status converged.
    end_early = wp_series_whole && target.reached(wp_series, collect_from_s, t) && !reached_end(t, end);
    return [&run, t, wp, wf, slurry, dt_s = st.dt_s,
            iterations = st.fluid.simple_iterations]() -> std::vector<double> {
      return {t,
              wp,
              wf,
              slurry,
              run.mean_particle_velocity(0),
              run.mean_particle_velocity(1),
              run.fluid().mean_pressure_gradient_pa_m(),
              dt_s,
              static_cast<double>(iterations),
              run.coupler().totals().min_alpha_f,
              run.dem().kinetic_energy_j()};
    };
  };
  const int exit_code = run_coupled_steps(run, out, before_step, measure, write_checkpoint, sb);
  out.flush();
  run.report_timers(timers);
  pdf_y = over_ranks(run, pdf_y);
  pdf_w = over_ranks(run, pdf_w);
  if (wp_avg.count()) {
    write_pdf(ctx.out_dir / "pdf_y.csv", "y_m", pdf_y);
    write_pdf(ctx.out_dir / "pdf_wp.csv", "wp_m_s", pdf_w);
  }
  if (budget) {
    run.set_force_budget(nullptr);
    for (stats::Histogram* h : budget->all()) *h = over_ranks(run, *h);
    const double vp = p.particle_volume_m3();
    const double weight =
        std::abs(p.particles.density_kg_m3 - p.fluid.density_kg_m3) * vp * p.gravity.magnitude_m_s2;
    if (output_rank() && budget->exposure().total_ > 0)
      write_file_atomic(ctx.out_dir / "force_budget_y.csv", budget->csv(weight > 0 ? weight : 1.0));
  }

  sb.simulated_time_s = run.time_s();
  sb.wall_time_s = wall_before + clock.seconds();
  const std::int64_t particles = run.dem().global_count();
  sb.particle_steps = static_cast<double>(particles) * static_cast<double>(run.dem().steps());
  sb.mean_settling_velocity_m_s = wp_avg.count() ? wp_avg.mean() : kUnset;
  const bool chose = p.time.average_from.automatic && wp_series_whole;
  const stats::ChosenWindow chosen = averaging_window(p.time.average_from, steps, wp_series, run.time_s());
  const stats::WindowError wp_err =
      stats::window_error(chosen.window, chosen.from_s, run.time_s(), sb.status == kStatusConverged);
  if (chose && !chosen.window.empty()) sb.mean_settling_velocity_m_s = wp_err.e.mean;
  sb.settling_velocity_stderr_m_s = wp_series_whole ? wp_err.err.stderr_of_mean : wp_avg.stderr_of_mean();
  auto j = make_summary(p, sb, timers);
  const bool finished = is_finished_status(sb.status);
  if (wp_series_whole) {
    report_settling_statistics(j, chosen.steps, chosen.window, wp_err, finished);
    if (p.time.average_from.automatic) j["pdfs_and_fluid_means_from_s"] = collect_from_s;
  } else {
    j["settling_velocity_error_method"] = "batch_means";
    if (finished)
      add_warning(j,
                  "resumed from a checkpoint of an earlier build, which kept no <w_p> series: the error of "
                  "<<w_p>> is from batch means, which ignore the correlation time");
  }
  // The estimate that earlier builds reported, for comparison.
  j["settling_velocity_stderr_batch_means_m_s"] = std::isfinite(wp_avg.stderr_of_mean())
                                                      ? nlohmann::json(wp_avg.stderr_of_mean())
                                                      : nlohmann::json(nullptr);
  const double rel = std::abs(sb.settling_velocity_stderr_m_s / sb.mean_settling_velocity_m_s);
  if (!wp_series_whole)
    j["settling_velocity_rel_stderr"] = std::isfinite(rel) ? nlohmann::json(rel) : nlohmann::json(nullptr);
  if (target.active()) {
    j["target_rel_error"] = p.time.target_rel_error;
    // Met: it stopped the run, or the whole window meets it at the end.
    // Judged as the run judges it (PrecisionTarget): on Sokal's covering error.
    const double covering_rel = std::abs(wp_err.e.covering_error / sb.mean_settling_velocity_m_s);
    j["target_met"] = sb.status == kStatusConverged ||
                      (wp_series_whole && covering_rel < p.time.target_rel_error &&
                       wp_err.e.correlation_times >= stats::PrecisionTarget::kMinCorrelationTimes);
  }
  j["ranks"] = run.rank_report();
  j["mean_fluid_velocity_m_s"] = wf_avg.count() ? wf_avg.mean() : kUnset;
  j["mean_slurry_velocity_m_s"] = slurry_avg.count() ? slurry_avg.mean() : kUnset;
  j["max_abs_slurry_velocity_m_s"] = slurry_max;
  j["isolated_terminal_velocity_m_s"] = vt;
  j["particle_count"] = particles;
  j["solid_fraction"] = p.solid_fraction();
  j["cfd_steps"] = run.steps();
  j["min_fluid_fraction"] = alpha_min_seen;
  j["max_fluid_fraction"] = alpha_max_seen;
  j["max_kinetic_energy_j"] = ke_max_seen;
  j["pressure_solver_fallbacks"] = run.pressure_fallbacks();
  j["unconverged_fluid_steps"] = run.unconverged_fluid_steps();
  j["dem_steps"] = run.dem().steps();
  // Of this attempt only (the count restarts when a run resumes): with the DEM steps of the
  // attempt it gives how often the neighbour list is rebuilt, which the cost depends on.
  j["neighbor_rebuilds_this_attempt"] = run.dem().rebuilds();
  j["samples_averaged"] = chose ? static_cast<std::int64_t>(chosen.window.size()) : wp_avg.count();
  j["resumed_from_checkpoint"] = resumed.has_value();
  j["pdf_outside_fraction"] = {{"y", pdf_y.total_ > 0 ? pdf_y.outside_ / pdf_y.total_ : 0.0},
                               {"wp", pdf_w.total_ > 0 ? pdf_w.outside_ / pdf_w.total_ : 0.0}};
  // A vertical suspension beside Richardson-Zaki: <<w_p>> is relative to zero volume flux, which
  // Eq. 25 holds. In a fully periodic box (homogeneous suspension) that is a validation error;
  // in a walled channel only a ratio (walls let it cluster and settle differently).
  if (std::abs(std::cos(p.gravity.angle_deg * kPi / 180.0)) < 1e-9) {
    const double re_t = p.fluid.density_kg_m3 * vt * p.particles.diameter_m / p.fluid.viscosity_pa_s;
    const double ref = -richardson_zaki_speed(vt, re_t, p.solid_fraction());
    j["hindered_settling_reference_m_s"] = ref;
    j["ratio_to_richardson_zaki"] = wp_avg.count() ? wp_avg.mean() / ref : kUnset;
    if (p.domain.periodic_y)
      j["hindered_settling_rel_error"] = wp_avg.count() ? (wp_avg.mean() - ref) / ref : kUnset;
  }
  j["wall_time_per_simulated_second_s"] = run.time_s() > 0 ? sb.wall_time_s / run.time_s() : kUnset;
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return exit_code;
}

}  // namespace boycott::scenes
