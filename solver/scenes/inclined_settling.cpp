// Scene inclined_settling (paper sections IV-V, Table III): a suspension settling in a narrow
// channel inclined at theta, periodic in x and z, walls at y = 0 and W, the slurry velocity held
// at zero by the driving gradient G (Eq. 25). Measures <w_p>(t) and <w_f>(t) (Eq. 28), the
// ensemble average <<w_p>> over [average_from, end] with its error from the autocorrelation of the
// whole <w_p> series over the window (stats/window_error.hpp, scenes/summary_statistics.hpp;
// Eq. 29), the PDFs of particle y and w_p over the same window (Fig. 12), and the particles'
// clustering in the x-z plane (Figs. 7, 13: coupling/cluster_index.hpp) every step. With
// time.target_rel_error it stops once <<w_p>> is that precise (status converged).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "coupling/cluster_index.hpp"
#include "coupling/drag_laws.hpp"
#include "coupling/velocity_profile.hpp"
#include "io/checkpoint_file.hpp"
#include "io/state_io.hpp"
#include "scenes/coupled_checkpoint.hpp"
#include "scenes/coupled_output.hpp"
#include "scenes/particle_setup.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"
#include "scenes/summarize.hpp"
#include "scenes/summary_statistics.hpp"
#include "stats/dispersion.hpp"
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

/// What the scene records over a run and carries across its checkpoints: <w_p>'s series (the
/// window's and the samples before it), the fluid and slurry means, the cluster index's mean, the
/// PDFs of y and w_p, the transverse force budget, the velocity profile across the gap, and the
/// stability record (alpha_f range, largest kinetic energy).
class SettlingRecord {
 public:
  SettlingRecord(const CaseParams& p, const coupling::CoupledSystem& run, double terminal_speed_m_s)
      : p_(p),
        pdf_y_(0.0, p.domain.width_y_m, static_cast<int>(p.output.pdf_bins)),
        // w_p range: a few isolated terminal speeds either way (values outside are counted apart).
        pdf_w_(-std::max(8.0 * terminal_speed_m_s, 0.05), 0.5 * std::max(8.0 * terminal_speed_m_s, 0.05),
               static_cast<int>(p.output.pdf_bins)),
        target_(p.time.target_rel_error, p.time.average_from.automatic),
        // With time.average_from = "auto" every step is collected and the window is cut at the end,
        // where the series shows its start-up transient over (the PDFs and fluid means keep all).
        collect_from_s_(p.time.average_from.collect_from_s()) {
    // The transverse force budget over the same window and bands as pdf_y (output.force_budget_y).
    if (p.output.force_budget_y)
      budget_.emplace(run.dem().config().box.lo[1], p.domain.width_y_m, static_cast<int>(p.output.pdf_bins));
    // The velocities per band, over the samples pdf_y takes (output.velocity_profile_y).
    if (p.output.velocity_profile_y)
      profile_.emplace(run.dem().config().box.lo[1], p.domain.width_y_m, static_cast<int>(p.output.pdf_bins));
  }

  /// The record of a checkpoint (the histograms on the output rank, which carries the sums of all).
  void load(const io::CheckpointReader& r);
  /// A checkpoint with the record, summed over ranks first on every rank (the writer runs on
  /// rank 0 alone, and a collective inside it would wait for ranks that never enter it).
  void checkpoint(const coupling::CoupledSystem& run, const std::filesystem::path& dir, const RunSpent& spent,
                  double next_out_s);
  /// Records the force budget from the window's start on.
  void before_step(coupling::CoupledSystem& run) {
    if (budget_) run.set_force_budget(run.time_s() >= collect_from_s_ - 1e-12 ? &*budget_ : nullptr);
  }
  /// Samples one step; `end_early` when time.target_rel_error is met before time.end. Returns the
  /// step's time-series row, made when the output asks for it.
  std::function<std::vector<double>()> measure(const coupling::CoupledSystem& run,
                                               const coupling::CoupledStep& st, bool& end_early);
  /// pdf_y.csv, pdf_wp.csv, force_budget_y.csv and velocity_profile_y.csv, the histograms summed
  /// over ranks.
  void write_distributions(coupling::CoupledSystem& run, const std::filesystem::path& dir) {
    write_pdfs_and_budget(run, dir);
    write_profile(run, dir);
  }
  /// summary.json: the common keys, <<w_p>> with its error, and the run's record.
  nlohmann::json summary(const coupling::CoupledSystem& run, SummaryBase& sb, const ModelTimers& timers,
                         double terminal_speed_m_s, bool resumed) const;

  double next_out_s() const { return next_out_; }

 private:
  void write_pdfs_and_budget(coupling::CoupledSystem& run, const std::filesystem::path& dir);
  void write_profile(coupling::CoupledSystem& run, const std::filesystem::path& dir);
  /// <<w_p>> over the chosen window with its error `wp_err`: into sb, then the summary's keys.
  nlohmann::json report_settling_velocity(SummaryBase& sb, const stats::ChosenWindow& chosen,
                                          const stats::WindowError& wp_err, const ModelTimers& timers) const;
  /// The run's own record: means, counts, stability, clustering, the vertical suspension's
  /// reference.
  void report_run_record(nlohmann::json& j, const coupling::CoupledSystem& run, double terminal_speed_m_s,
                         bool resumed) const;
  /// The cluster index's mean over the steps of the fluid means, with the scatter that one
  /// sample of these particles placed at random in these columns has (1 +- that is random).
  void report_clustering(nlohmann::json& j, const coupling::CoupledSystem& run) const;

  const CaseParams& p_;
  stats::Histogram pdf_y_, pdf_w_;
  std::optional<coupling::ForceBudget> budget_;
  std::optional<coupling::VelocityProfile> profile_;
  stats::BatchMeans wp_avg_, wf_avg_, slurry_avg_;
  /// The cluster index over the steps the fluid means take (none before a resume of a build
  /// that kept none: then from the resume on, cluster_index_samples says how many).
  stats::BatchMeans cluster_avg_;
  /// Every <w_p> sample of the window, for its error (20 s of 1 ms steps: 15 000 doubles).
  std::vector<double> wp_series_;
  bool wp_series_whole_ = true;  ///< false after resuming a checkpoint of a build that kept none
  /// The samples before the window (the transient's detection) and the step lengths (s) of all.
  stats::StepSeries steps_;
  stats::PrecisionTarget target_;
  double collect_from_s_;
  double slurry_max_ = 0.0;
  double next_out_ = 0.0;  ///< the resumed output's next row, s
  double alpha_min_seen_ = 1.0, alpha_max_seen_ = 0.0, ke_max_seen_ = 0.0;
};

void SettlingRecord::load(const io::CheckpointReader& r) {
  io::load(r, "stats.wp.", wp_avg_);
  io::load(r, "stats.wf.", wf_avg_);
  io::load(r, "stats.slurry.", slurry_avg_);
  if (r.has("stats.cluster.ints")) io::load(r, "stats.cluster.", cluster_avg_);
  // The histograms are counts over all ranks: rank 0 carries them on, the others add theirs.
  if (output_rank()) {
    io::load(r, "stats.pdf_y.", pdf_y_);
    io::load(r, "stats.pdf_w.", pdf_w_);
    // A run that was not recording its budget has none to carry on (it starts now).
    if (budget_ && r.has("stats.budget.0.counts")) {
      const auto h = budget_->all();
      for (std::size_t k = 0; k < h.size(); ++k) io::load(r, fmt::format("stats.budget.{}.", k), *h[k]);
    }
    if (profile_ && r.has("stats.profile.0.counts")) {
      const auto h = profile_->all();
      for (std::size_t k = 0; k < h.size(); ++k) io::load(r, fmt::format("stats.profile.{}.", k), *h[k]);
    }
  }
  slurry_max_ = r.scalar("stats.slurry_max");
  next_out_ = r.scalar("stats.next_out");
  if (r.has("stats.alpha_min_seen")) {  // absent in checkpoints of earlier builds
    alpha_min_seen_ = r.scalar("stats.alpha_min_seen");
    alpha_max_seen_ = r.scalar("stats.alpha_max_seen");
    ke_max_seen_ = r.scalar("stats.ke_max_seen");
  }
  steps_ = read_step_series(r);
  if (r.has("stats.wp_series")) {
    wp_series_ = r.doubles("stats.wp_series");
    target_.from_state(r.doubles("stats.target"));
  } else {
    wp_series_whole_ = wp_avg_.count() == 0;
  }
}

void SettlingRecord::checkpoint(const coupling::CoupledSystem& run, const std::filesystem::path& dir,
                                const RunSpent& spent, double next_out_s) {
  const stats::Histogram all_y = over_ranks(run, pdf_y_), all_w = over_ranks(run, pdf_w_);
  std::vector<stats::Histogram> all_budget;
  if (budget_)
    for (const stats::Histogram* h : budget_->all()) all_budget.push_back(over_ranks(run, *h));
  std::vector<stats::Histogram> all_profile;
  if (profile_)
    for (const stats::Histogram* h : profile_->all()) all_profile.push_back(over_ranks(run, *h));
  checkpoint_coupled(run, dir, spent, [&](io::CheckpointWriter& w) {
    io::save(w, "stats.wp.", wp_avg_);
    io::save(w, "stats.wf.", wf_avg_);
    io::save(w, "stats.slurry.", slurry_avg_);
    io::save(w, "stats.pdf_y.", all_y);
    io::save(w, "stats.pdf_w.", all_w);
    for (std::size_t k = 0; k < all_budget.size(); ++k)
      io::save(w, fmt::format("stats.budget.{}.", k), all_budget[k]);
    for (std::size_t k = 0; k < all_profile.size(); ++k)
      io::save(w, fmt::format("stats.profile.{}.", k), all_profile[k]);
    io::save(w, "stats.cluster.", cluster_avg_);
    w.put("stats.slurry_max", slurry_max_);
    w.put("stats.next_out", next_out_s);
    w.put("stats.alpha_min_seen", alpha_min_seen_);
    w.put("stats.alpha_max_seen", alpha_max_seen_);
    w.put("stats.ke_max_seen", ke_max_seen_);
    w.put("stats.wp_series", wp_series_);
    write_step_series(w, steps_);
    w.put("stats.target", target_.to_state());
  });
}

std::function<std::vector<double>()> SettlingRecord::measure(const coupling::CoupledSystem& run,
                                                             const coupling::CoupledStep& st,
                                                             bool& end_early) {
  const auto& s = run.dem().particles();
  const double t = run.time_s();
  const double wp = run.mean_particle_velocity(2);
  const double wf = run.mean_fluid_velocity_z();
  const double slurry = run.slurry_velocity_z();
  const double cluster = coupling::xz_cluster_index(run);
  alpha_min_seen_ = std::min(alpha_min_seen_, run.coupler().totals().min_alpha_f);
  alpha_max_seen_ = std::max(alpha_max_seen_, run.coupler().totals().max_alpha_f);
  ke_max_seen_ = std::max(ke_max_seen_, run.dem().kinetic_energy_j());
  if (t > collect_from_s_ + 1e-12) {
    wp_avg_.add(wp);
    wp_series_.push_back(wp);
    steps_.window_dt.push_back(st.dt_s);
    wf_avg_.add(wf);
    slurry_avg_.add(slurry);
    if (std::isfinite(cluster)) cluster_avg_.add(cluster);
    slurry_max_ = std::max(slurry_max_, std::abs(slurry));
    for (std::size_t i = 0; i < s.n_local; ++i) {
      pdf_y_.add(s.y[i]);
      pdf_w_.add(s.vz[i]);
    }
    if (profile_) profile_->add(s);
  } else {
    steps_.before.push_back(wp);
    steps_.before_dt.push_back(st.dt_s);
  }
  // time.target_rel_error met before time.end: the last row, a checkpoint, status converged.
  end_early =
      wp_series_whole_ && target_.reached(wp_series_, collect_from_s_, t) && !reached_end(t, p_.time.end_s);
  return [&run, t, wp, wf, slurry, cluster, dt_s = st.dt_s,
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
            run.dem().kinetic_energy_j(),
            cluster};
  };
}

void SettlingRecord::write_pdfs_and_budget(coupling::CoupledSystem& run, const std::filesystem::path& dir) {
  pdf_y_ = over_ranks(run, pdf_y_);
  pdf_w_ = over_ranks(run, pdf_w_);
  if (wp_avg_.count()) {
    write_pdf(dir / "pdf_y.csv", "y_m", pdf_y_);
    write_pdf(dir / "pdf_wp.csv", "wp_m_s", pdf_w_);
  }
  if (!budget_) return;
  run.set_force_budget(nullptr);
  for (stats::Histogram* h : budget_->all()) *h = over_ranks(run, *h);
  const double vp = p_.particle_volume_m3();
  const double weight =
      std::abs(p_.particles.density_kg_m3 - p_.fluid.density_kg_m3) * vp * p_.gravity.magnitude_m_s2;
  if (output_rank() && budget_->exposure().total_ > 0)
    write_file_atomic(dir / "force_budget_y.csv", budget_->csv(weight > 0 ? weight : 1.0));
}

void SettlingRecord::write_profile(coupling::CoupledSystem& run, const std::filesystem::path& dir) {
  if (!profile_) return;
  for (stats::Histogram* h : profile_->all()) *h = over_ranks(run, *h);
  if (output_rank() && profile_->sums(coupling::VelocityProfile::samples).total_ > 0)
    write_file_atomic(dir / "velocity_profile_y.csv", profile_->csv());
}

nlohmann::json SettlingRecord::summary(const coupling::CoupledSystem& run, SummaryBase& sb,
                                       const ModelTimers& timers, double terminal_speed_m_s,
                                       bool resumed) const {
  // A run its precision target stopped reports the target's two-stage error, over the window its
  // first stage fixed.
  const stats::TwoStagePlan* plan = sb.status == kStatusConverged ? &target_.plan() : nullptr;
  const stats::ChosenWindow chosen =
      averaging_window(p_.time.average_from, steps_, wp_series_, run.time_s(), plan);
  const stats::WindowError wp_err = stats::window_error(chosen.window, chosen.from_s, run.time_s(), plan);
  nlohmann::json j = report_settling_velocity(sb, chosen, wp_err, timers);
  const bool chose = p_.time.average_from.automatic && wp_series_whole_;
  j["samples_averaged"] = chose ? static_cast<std::int64_t>(chosen.window.size()) : wp_avg_.count();
  report_run_record(j, run, terminal_speed_m_s, resumed);
  j["wall_time_per_simulated_second_s"] = run.time_s() > 0 ? sb.wall_time_s / run.time_s() : kUnset;
  return j;
}

nlohmann::json SettlingRecord::report_settling_velocity(SummaryBase& sb, const stats::ChosenWindow& chosen,
                                                        const stats::WindowError& wp_err,
                                                        const ModelTimers& timers) const {
  sb.mean_settling_velocity_m_s = wp_avg_.count() ? wp_avg_.mean() : kUnset;
  const bool chose = p_.time.average_from.automatic && wp_series_whole_;
  if (chose && !chosen.window.empty()) sb.mean_settling_velocity_m_s = wp_err.e.mean;
  sb.settling_velocity_stderr_m_s = wp_series_whole_ ? wp_err.err.stderr_of_mean : wp_avg_.stderr_of_mean();
  nlohmann::json j = make_summary(p_, sb, timers);
  const bool finished = is_finished_status(sb.status);
  if (wp_series_whole_) {
    report_settling_statistics(j, chosen.steps, chosen.window, wp_err, finished);
    if (p_.time.average_from.automatic) j["pdfs_and_fluid_means_from_s"] = collect_from_s_;
  } else {
    j["settling_velocity_error_method"] = "batch_means";
    if (finished)
      add_warning(j,
                  "resumed from a checkpoint of an earlier build, which kept no <w_p> series: the error of "
                  "<<w_p>> is from batch means, which ignore the correlation time");
  }
  // The estimate that earlier builds reported, for comparison.
  j["settling_velocity_stderr_batch_means_m_s"] = std::isfinite(wp_avg_.stderr_of_mean())
                                                      ? nlohmann::json(wp_avg_.stderr_of_mean())
                                                      : nlohmann::json(nullptr);
  const double rel = std::abs(sb.settling_velocity_stderr_m_s / sb.mean_settling_velocity_m_s);
  if (!wp_series_whole_)
    j["settling_velocity_rel_stderr"] = std::isfinite(rel) ? nlohmann::json(rel) : nlohmann::json(nullptr);
  if (target_.active()) {
    j["target_rel_error"] = p_.time.target_rel_error;
    // Met: it stopped the run, or the window's own error meets it at the end.
    const double covering_rel = std::abs(wp_err.err.covering_error / sb.mean_settling_velocity_m_s);
    j["target_met"] =
        sb.status == kStatusConverged || (wp_series_whole_ && covering_rel < p_.time.target_rel_error);
  }
  return j;
}

void SettlingRecord::report_run_record(nlohmann::json& j, const coupling::CoupledSystem& run,
                                       double terminal_speed_m_s, bool resumed) const {
  const double vt = terminal_speed_m_s;
  j["ranks"] = run.rank_report();
  j["mean_fluid_velocity_m_s"] = wf_avg_.count() ? wf_avg_.mean() : kUnset;
  j["mean_slurry_velocity_m_s"] = slurry_avg_.count() ? slurry_avg_.mean() : kUnset;
  j["max_abs_slurry_velocity_m_s"] = slurry_max_;
  j["isolated_terminal_velocity_m_s"] = vt;
  j["particle_count"] = run.dem().global_count();
  j["solid_fraction"] = p_.solid_fraction();
  j["cfd_steps"] = run.steps();
  j["min_fluid_fraction"] = alpha_min_seen_;
  j["max_fluid_fraction"] = alpha_max_seen_;
  j["max_kinetic_energy_j"] = ke_max_seen_;
  j["pressure_solver_fallbacks"] = run.pressure_fallbacks();
  j["unconverged_fluid_steps"] = run.unconverged_fluid_steps();
  j["dem_steps"] = run.dem().steps();
  // Of this attempt only (the count restarts when a run resumes): with the DEM steps of the
  // attempt it gives how often the neighbour list is rebuilt, which the cost depends on.
  j["neighbor_rebuilds_this_attempt"] = run.dem().rebuilds();
  j["resumed_from_checkpoint"] = resumed;
  report_clustering(j, run);
  j["pdf_outside_fraction"] = {{"y", pdf_y_.total_ > 0 ? pdf_y_.outside_ / pdf_y_.total_ : 0.0},
                               {"wp", pdf_w_.total_ > 0 ? pdf_w_.outside_ / pdf_w_.total_ : 0.0}};
  // A vertical suspension beside Richardson-Zaki: <<w_p>> is relative to zero volume flux, which
  // Eq. 25 holds. In a fully periodic box (homogeneous suspension) that is a validation error;
  // in a walled channel only a ratio (walls let it cluster and settle differently).
  if (std::abs(std::cos(p_.gravity.angle_deg * kPi / 180.0)) < 1e-9) {
    const double re_t = p_.fluid.density_kg_m3 * vt * p_.particles.diameter_m / p_.fluid.viscosity_pa_s;
    const double ref = -richardson_zaki_speed(vt, re_t, p_.solid_fraction());
    j["hindered_settling_reference_m_s"] = ref;
    j["ratio_to_richardson_zaki"] = wp_avg_.count() ? wp_avg_.mean() / ref : kUnset;
    if (p_.domain.periodic_y)
      j["hindered_settling_rel_error"] = wp_avg_.count() ? (wp_avg_.mean() - ref) / ref : kUnset;
  }
}

void SettlingRecord::report_clustering(nlohmann::json& j, const coupling::CoupledSystem& run) const {
  const std::int64_t columns = p_.domain.cells[0] * p_.domain.cells[2];
  j["cluster_index_mean"] = cluster_avg_.count() ? cluster_avg_.mean() : kUnset;
  const double se = cluster_avg_.stderr_of_mean();
  j["cluster_index_stderr_batch_means"] = std::isfinite(se) ? nlohmann::json(se) : nlohmann::json(nullptr);
  j["cluster_index_samples"] = cluster_avg_.count();
  j["cluster_index_columns"] = columns;
  const double sd = stats::dispersion_index_random_sd(run.dem().global_count(), columns);
  j["cluster_index_random_sd"] = std::isfinite(sd) ? nlohmann::json(sd) : nlohmann::json(nullptr);
}

}  // namespace

int run_inclined_settling(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true});
  const double vt = isolated_terminal_speed(p);
  SettlingRecord record(p, run, vt);
  const auto resumed = resume_coupled(
      run, ctx.out_dir, ctx.quiet, [&](const io::CheckpointReader& r) { record.load(r); },
      ctx.branch_checkpoint);
  if (resumed) {
    carry_spent(*resumed, clock, timers);
  } else {
    insert_case_particles(run.dem(), p);
    run.start();
  }
  run.activate_models(timers);
  SummaryBase sb;
  const int exit_code = run_recorded_steps(
      run, ctx, timers, record,
      {"time_s", "mean_wp_m_s", "mean_wf_m_s", "slurry_velocity_m_s", "mean_up_m_s", "mean_vp_m_s",
       "driving_gradient_pa_m", "dt_s", "simple_iterations", "min_alpha_f", "kinetic_energy_j",
       "cluster_index"},
      resumed.has_value(), clock, [&] { record.before_step(run); },
      [&](const coupling::CoupledStep& st, bool& end_early) { return record.measure(run, st, end_early); },
      sb);
  run.report_timers(timers);
  record.write_distributions(run, ctx.out_dir);
  set_run_totals(sb, run, clock.spent());
  const auto j = record.summary(run, sb, timers, vt, resumed.has_value());
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return exit_code;
}

namespace {

/// A fully periodic box holds the weight only through the z driving gradient: vertical alone. And
/// an unresolved shear without a subgrid model, where the channel's own flow makes one.
void inclined_settling_checks(const CaseParams& p, SceneFindings& f) {
  if (p.domain.periodic_y && std::abs(std::cos(p.gravity.angle_deg * kPi / 180.0)) > 1e-9)
    f.errors.push_back(
        fmt::format("domain.periodic_y = true needs gravity.angle_deg = 90, not {}: in a fully periodic "
                    "box only the z driving gradient holds the weight (homogeneous suspension)",
                    p.gravity.angle_deg));
  if (p.fluid.subgrid_model != "none" || p.forces.drag == "none") return;
  const double dx_min =
      std::min({p.domain.length_x_m / p.domain.cells[0], p.domain.width_y_m / p.domain.cells[1],
                p.domain.height_z_m / p.domain.cells[2]});
  const double cell_re =
      3.0 * isolated_terminal_speed(p) * dx_min * p.fluid.density_kg_m3 / p.fluid.viscosity_pa_s;
  if (cell_re > 10.0)
    f.warnings.push_back(
        fmt::format("cell Reynolds number 3 w_t dx / nu = {:.3g} > 10 with fluid.subgrid_model = "
                    "\"none\": unresolved shear is not modelled",
                    cell_re));
}

std::vector<std::string> inclined_settling_keys() {
  auto keys = coupled_scene_keys();
  keys.emplace_back("output.");
  return keys;
}

}  // namespace

const SceneRegistration kRegistered{
    {.name = "inclined_settling",
     .measures = "<<w_p>> over [average_from, end] with its error, <w_p>(t), PDFs of y and w_p, cluster "
                 "index, images",
     .reads = inclined_settling_keys(),
     .default_solid_fraction = table3_solid_fraction(),
     .tolerances = {{"hindered_settling_rel_error", 0.15, "Richardson-Zaki, periodic suspension"}},
     .detects_transient = true,
     .own_checks = &inclined_settling_checks},
    &run_inclined_settling};

}  // namespace boycott::scenes
