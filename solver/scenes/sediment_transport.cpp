// Scene sediment_transport (paper section III B, Table II; issue 7): a particle bed on a no-slip
// wall at y = 0 under gravity -y, a slip (mirror) top at y = H, periodic x and z, the fluid
// driven in +z by a uniform pressure gradient G(t) that holds the box mean of alpha_f w at
// sediment.bulk_velocity. Measures the dimensionless transport rate (Eq. 23)
//   q* = sum_i V_p u_p,z / A / sqrt((rho_p/rho_f - 1) g d^3),  A = L_x L_z,
// and the Shields stress tau* = tau_b / ((rho_p - rho_f) g d). The paper's printed Eq. 24 is not
// dimensionless; tau_b is taken from the momentum balance of the fluid column above the bed: in
// a statistically steady state the driving force on that column, -G (H - h_b) per unit area,
// is carried by the bed surface, so tau_b = -<G> (H - h_b), with h_b the bed height (particle
// volume over A and the packed fraction 0.6, the fraction a poured bed settles to here).
// References:
//   Wong & Parker (2006), J. Hydraul. Eng. 132, 1159: q* = 3.97 (tau* - 0.0495)^1.5 (bed load);
//   Nielsen (1992), Coastal Bottom Boundary Layers and Sediment Transport, World Scientific:
//   q* = 12 tau*^0.5 (tau* - 0.05), the form Schmeeckle (2014, JGR Earth Surf. 119, 1240) and
//   Sun & Xiao (2016, Comput. Geosci. 89, 207) compare their CFD-DEM transport rates with.
// The fluid starts turbulent over the poured bed (sediment.initial_flow, fluid/turbulent_start.hpp).
// From rest, the flux controller's first step kicks the bed with a gradient of ~-2e6 Pa/m; the
// bed is then eroded and the flow relaminarises (5 x 10 mm plan) or it is blown into suspension,
// which trips the turbulence (10 x 20 mm). Started turbulent, the flow needs neither.
// Writes profiles.csv (time-averaged rows over y) and snapshots at output.snapshot_times.
// Checkpoints as inclined_settling: every time.checkpoint_every, at the end, and on SIGINT/SIGTERM
// (exit 75); the same command resumes.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "fluid/turbulent_start.hpp"
#include "io/checkpoint_file.hpp"
#include "io/state_io.hpp"
#include "scenes/coupled_checkpoint.hpp"
#include "scenes/coupled_output.hpp"
#include "scenes/particle_setup.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"
#include "stats/running.hpp"

namespace boycott::scenes {

namespace {
constexpr double kBedPackedFraction = 0.6;

// Steps the DEM alone until the kinetic energy per particle is below 1e-4 m g d (a resting bed;
// the settled-bed test of the DEM reaches 1.4e-7), at most 2 s. Returns the pouring time, s.
double settle_bed(particles::DemSystem& dem, const CaseParams& p) {
  dem.initialize();
  auto& s = dem.particles();
  const double threshold = 1e-4 * p.particle_mass_kg() * p.gravity.magnitude_m_s2 * p.particles.diameter_m;
  const int check_every = std::max(1, static_cast<int>(std::lround(0.01 / p.time.dt_dem_s)));
  double t = 0.0;
  while (t < 2.0) {
    dem.advance(check_every);
    t += check_every * p.time.dt_dem_s;
    if (s.n_local == 0 || dem.kinetic_energy_j() / static_cast<double>(s.n_local) < threshold) break;
  }
  for (std::size_t i = 0; i < s.n_local; ++i) s.vx[i] = s.vy[i] = s.vz[i] = s.wx[i] = s.wy[i] = s.wz[i] = 0.0;
  return t;
}

// Time-averaged profiles over y (per fluid cell row) for profiles.csv: the plane mean of the
// fluid's w, and the particles binned by centre (solid fraction, their mean w, their flux
// density, whose integral over y is the transport rate q).
struct Profiles {
  std::vector<double> fluid_w, solid_volume, particle_flux;  // sums over steps: m/s, m^3, m^4/s
  double steps = 0.0;
  explicit Profiles(std::size_t ny) : fluid_w(ny, 0.0), solid_volume(ny, 0.0), particle_flux(ny, 0.0) {}
  void add(fluid::FluidSolver& f, const particles::ParticleStore& s, double h) {
    const auto w = f.profile_y(2);
    for (std::size_t j = 0; j < fluid_w.size(); ++j) fluid_w[j] += w[j];
    const auto ny = static_cast<std::int64_t>(fluid_w.size());
    for (std::size_t i = 0; i < s.n_local; ++i) {
      const auto j = std::clamp(static_cast<std::int64_t>(std::floor(s.y[i] / h)), std::int64_t{0}, ny - 1);
      const double v = (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i];
      solid_volume[j] += v;
      particle_flux[j] += v * s.vz[i];
    }
    steps += 1.0;
  }
  /// The particle sums of every rank (the fluid profile is the same on all of them).
  Profiles over_ranks(const coupling::CoupledSystem& run) const {
    Profiles all = *this;
    for (auto* v : {&all.solid_volume, &all.particle_flux})
      for (double& x : *v) x = run.global_sum(x);
    return all;
  }
  void save(io::CheckpointWriter& w) const {
    w.put("stats.profile.fluid_w", fluid_w);
    w.put("stats.profile.solid_volume", solid_volume);
    w.put("stats.profile.particle_flux", particle_flux);
    w.put("stats.profile.steps", steps);
  }
  /// The particle sums go to rank 0, which carries on the all-rank totals (the others add theirs).
  void load(const io::CheckpointReader& r) {
    fluid_w = r.doubles("stats.profile.fluid_w");
    if (output_rank()) {
      solid_volume = r.doubles("stats.profile.solid_volume");
      particle_flux = r.doubles("stats.profile.particle_flux");
    }
    steps = r.scalar("stats.profile.steps");
  }
  void write(const std::filesystem::path& path, double h, double area) const {
    CsvWriter csv(
        path, {"y_m", "fluid_w_m_s", "solid_fraction", "particle_w_m_s", "particle_flux_density_m_s"}, false);
    for (std::size_t j = 0; j < fluid_w.size(); ++j) {
      const double n = std::max(steps, 1.0), cell = area * h * n;
      csv.row({(j + 0.5) * h, fluid_w[j] / n, solid_volume[j] / cell,
               solid_volume[j] > 0.0 ? particle_flux[j] / solid_volume[j] : 0.0, particle_flux[j] / cell});
    }
  }
};

double wong_parker_q(double tau) {
  return tau > 0.0495 ? 3.97 * std::pow(tau - 0.0495, 1.5) : 0.0;
}
double nielsen_q(double tau) {
  return tau > 0.05 ? 12.0 * std::sqrt(tau) * (tau - 0.05) : 0.0;
}

/// The bed height the flow sees, m: given, or the particles' volume packed at kBedPackedFraction
/// over the bottom (particle volume is conserved, so the same before pouring and on resume).
double bed_height_m(const CaseParams& p, double particle_volume_m3) {
  const double area = p.domain.length_x_m * p.domain.height_z_m;
  return is_set(p.sediment.bed_height_m) ? p.sediment.bed_height_m
                                         : particle_volume_m3 / (area * kBedPackedFraction);
}

/// A new run: the paper starts from a bed packed on the bottom, poured dry (DEM only, still fluid
/// left out) until it rests, before the flow starts (this time is not simulated time); then the
/// flow, turbulent over the bed top with Nikuradse's k_s = 2.5 d unless it starts from rest.
/// Returns the pouring time, s.
double pour_bed_and_start_flow(coupling::CoupledSystem& run, const CaseParams& p, ModelTimers& timers) {
  insert_case_particles(run.dem(), p);
  double settle_s = 0.0;
  {
    ModelTimers::Scope sc(timers, "bed_pouring");
    settle_s = settle_bed(run.dem(), p);
  }
  const double floor_m = bed_height_m(p, run.particle_volume_m3());
  run.start();
  if (p.sediment.initial_flow == "turbulent") {
    fluid::TurbulentStartSettings ts;
    ts.bulk_velocity_m_s = p.sediment.bulk_velocity_m_s;
    ts.floor_m = floor_m;
    ts.roughness_m = 2.5 * p.particles.diameter_m;
    ts.seed = static_cast<std::uint64_t>(p.seed);
    fluid::start_turbulent_channel(run.fluid(), ts);
  }
  return settle_s;
}

/// What the scene records over a run and carries across its checkpoints: the transport rate,
/// driving gradient, flux and transverse particle velocity over the window, the profiles over y,
/// the stability record and the bed's pouring time.
class TransportRecord {
 public:
  explicit TransportRecord(const CaseParams& p)
      : p_(p),
        h_y_(p.domain.width_y_m / static_cast<double>(p.domain.cells[1])),
        area_(p.domain.length_x_m * p.domain.height_z_m),
        q_scale_(std::sqrt((p.particles.density_kg_m3 / p.fluid.density_kg_m3 - 1.0) *
                           p.gravity.magnitude_m_s2 * p.particles.diameter_m * p.particles.diameter_m *
                           p.particles.diameter_m)),
        profiles_(static_cast<std::size_t>(p.domain.cells[1])) {}

  void load(const io::CheckpointReader& r) {
    for (auto [name, b] : averages()) io::load(r, fmt::format("stats.{}.", name), *b);
    alpha_min_seen_ = r.scalar("stats.alpha_min_seen");
    ke_max_seen_ = r.scalar("stats.ke_max_seen");
    next_out_ = r.scalar("stats.next_out");
    settle_s_ = r.scalar("stats.bed_pouring_time_s");
    profiles_.load(r);
  }
  /// A checkpoint with the record (the profiles' particle sums over ranks first, on every rank).
  void checkpoint(const coupling::CoupledSystem& run, const std::filesystem::path& dir, const RunSpent& spent,
                  double next_out_s) {
    const Profiles all_profiles = profiles_.over_ranks(run);
    checkpoint_coupled(run, dir, spent, [&](io::CheckpointWriter& w) {
      for (auto [name, b] : averages()) io::save(w, fmt::format("stats.{}.", name), *b);
      w.put("stats.alpha_min_seen", alpha_min_seen_);
      w.put("stats.ke_max_seen", ke_max_seen_);
      w.put("stats.next_out", next_out_s);
      w.put("stats.bed_pouring_time_s", settle_s_);
      all_profiles.save(w);
    });
  }
  /// Samples one step; returns its time-series row, made when the output asks for it.
  std::function<std::vector<double>()> measure(coupling::CoupledSystem& run, const coupling::CoupledStep& st);
  /// profiles.csv, summed over ranks.
  void write_profiles(const coupling::CoupledSystem& run, const std::filesystem::path& dir) const {
    profiles_.over_ranks(run).write(dir / "profiles.csv", h_y_, area_);
  }
  /// summary.json: the common keys, q* against the Shields stress and the run's record.
  nlohmann::json summary(const coupling::CoupledSystem& run, SummaryBase& sb, const ModelTimers& timers,
                         double h_bed, bool resumed) const;

  void set_pouring_time(double s) { settle_s_ = s; }
  double next_out_s() const { return next_out_; }

 private:
  std::array<std::pair<const char*, stats::BatchMeans*>, 4> averages() {
    return {{{"q", &q_avg_}, {"g", &g_avg_}, {"wf", &wf_avg_}, {"vp", &vp_avg_}}};
  }
  /// Particle volume flux along z per unit bed area over all ranks, m^2/s.
  double transport_rate_m2_s(const coupling::CoupledSystem& run) const {
    const auto& s = run.dem().particles();
    double q = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i)
      q += (4.0 / 3.0) * kPi * s.radius[i] * s.radius[i] * s.radius[i] * s.vz[i];
    return run.global_sum(q) / area_;
  }

  const CaseParams& p_;
  double h_y_, area_;  ///< fluid cell height (m) and bed area (m^2)
  double q_scale_;     ///< sqrt((s - 1) g d^3), m^2/s: q* = q / q_scale
  stats::BatchMeans q_avg_, g_avg_, wf_avg_, vp_avg_;
  Profiles profiles_;
  double alpha_min_seen_ = 1.0, ke_max_seen_ = 0.0, settle_s_ = 0.0;
  double next_out_ = 0.0;  ///< the resumed output's next row, s
};

std::function<std::vector<double>()> TransportRecord::measure(coupling::CoupledSystem& run,
                                                              const coupling::CoupledStep& st) {
  const double t = run.time_s();
  const double q = transport_rate_m2_s(run);
  const double G = run.fluid().mean_pressure_gradient_pa_m();
  alpha_min_seen_ = std::min(alpha_min_seen_, run.coupler().totals().min_alpha_f);
  ke_max_seen_ = std::max(ke_max_seen_, run.dem().kinetic_energy_j());
  if (t > p_.time.average_from.time_s + 1e-12) {
    q_avg_.add(q);
    g_avg_.add(G);
    wf_avg_.add(run.fluid().mean_flux_z());
    vp_avg_.add(run.mean_particle_velocity(1));
    profiles_.add(run.fluid(), run.dem().particles(), h_y_);
  }
  return [&run, t, q, q_scale = q_scale_, G, dt_s = st.dt_s,
          iterations = st.fluid.simple_iterations]() -> std::vector<double> {
    return {t,
            q,
            q / q_scale,
            G,
            run.fluid().mean_flux_z(),
            run.mean_particle_velocity(2),
            run.mean_particle_velocity(1),
            dt_s,
            static_cast<double>(iterations),
            run.coupler().totals().min_alpha_f,
            run.dem().kinetic_energy_j()};
  };
}

nlohmann::json TransportRecord::summary(const coupling::CoupledSystem& run, SummaryBase& sb,
                                        const ModelTimers& timers, double h_bed, bool resumed) const {
  const double H = p_.domain.width_y_m, d = p_.particles.diameter_m, g = p_.gravity.magnitude_m_s2;
  const double rho_p = p_.particles.density_kg_m3, rho_f = p_.fluid.density_kg_m3;
  sb.mean_settling_velocity_m_s = vp_avg_.count() ? vp_avg_.mean() : kUnset;
  sb.settling_velocity_stderr_m_s = vp_avg_.stderr_of_mean();
  auto j = make_summary(p_, sb, timers);
  j["ranks"] = run.rank_report();
  const double q = q_avg_.count() ? q_avg_.mean() : kUnset;
  const double Gm = g_avg_.count() ? g_avg_.mean() : kUnset;
  const double tau_b = -Gm * (H - h_bed);
  const double tau_star = tau_b / ((rho_p - rho_f) * g * d);
  const double q_star = q / q_scale_;
  j["bulk_velocity_target_m_s"] = p_.sediment.bulk_velocity_m_s;
  j["mean_flux_z_m_s"] = wf_avg_.count() ? wf_avg_.mean() : kUnset;
  j["transport_rate_m2_s"] = q;
  j["transport_rate_stderr_m2_s"] = q_avg_.stderr_of_mean();
  j["q_star"] = q_star;
  j["q_star_stderr"] = q_avg_.stderr_of_mean() / q_scale_;
  j["mean_driving_gradient_pa_m"] = Gm;
  j["bed_height_m"] = h_bed;
  j["bed_pouring_time_s"] = settle_s_;
  j["resumed_from_checkpoint"] = resumed;
  j["bed_shear_stress_pa"] = tau_b;
  j["shields_stress"] = tau_star;
  const double qwp = wong_parker_q(tau_star), qn = nielsen_q(tau_star);
  j["q_star_wong_parker"] = qwp;
  j["q_star_nielsen"] = qn;
  // Relative distance to each curve (null where the curve gives no transport).
  j["wong_parker_rel_error"] = qwp > 0.0 ? nlohmann::json((q_star - qwp) / qwp) : nlohmann::json(nullptr);
  j["nielsen_rel_error"] = qn > 0.0 ? nlohmann::json((q_star - qn) / qn) : nlohmann::json(nullptr);
  j["particle_count"] = run.dem().global_count();
  j["min_fluid_fraction"] = alpha_min_seen_;
  j["max_kinetic_energy_j"] = ke_max_seen_;
  j["cfd_steps"] = run.steps();
  j["dem_steps"] = run.dem().steps();
  j["pressure_solver_fallbacks"] = run.pressure_fallbacks();
  j["unconverged_fluid_steps"] = run.unconverged_fluid_steps();
  return j;
}

}  // namespace

int run_sediment_transport(const CaseParams& p, RunContext& ctx) {
  // The geometry (theta = 0, walls in y, a bed below the top) is checked by the pre-flight.
  RunClock clock;
  ModelTimers timers;
  coupling::CoupledOptions opt;
  opt.zero_slurry_flux = false;
  opt.target_mean_flux_z_m_s = p.sediment.bulk_velocity_m_s;
  coupling::CoupledSystem run(p, opt);
  TransportRecord record(p);
  timers.activate("bed_pouring", "dry DEM until the bed rests");
  const auto resumed = resume_coupled(
      run, ctx.out_dir, ctx.quiet, [&](const io::CheckpointReader& r) { record.load(r); },
      ctx.branch_checkpoint);
  if (resumed)
    carry_spent(*resumed, clock, timers);
  else
    record.set_pouring_time(pour_bed_and_start_flow(run, p, timers));
  const double h_bed = bed_height_m(p, run.particle_volume_m3());
  run.activate_models(timers);
  timers.activate("flux_controller",
                  fmt::format("G(t) holds mean alpha_f w = {} m/s", p.sediment.bulk_velocity_m_s));
  SummaryBase sb;
  const int exit_code = run_recorded_steps(
      run, ctx, timers, record,
      {"time_s", "q_m2_s", "q_star", "driving_gradient_pa_m", "mean_flux_z_m_s", "mean_up_z_m_s",
       "mean_vp_m_s", "dt_s", "simple_iterations", "min_alpha_f", "kinetic_energy_j"},
      resumed.has_value(), clock, [] {},
      [&](const coupling::CoupledStep& st, bool&) { return record.measure(run, st); }, sb);
  record.write_profiles(run, ctx.out_dir);
  run.report_timers(timers);
  set_run_totals(sb, run, clock.spent());
  const auto j = record.summary(run, sb, timers, h_bed, resumed.has_value());
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  if (!ctx.quiet && output_rank())
    std::printf(
        "sediment_transport: t = %.4g s, q* = %.4g, tau* = %.4g (Wong-Parker q* %.4g, Nielsen %.4g)\n",
        run.time_s(), j["q_star"].get<double>(), j["shields_stress"].get<double>(),
        j["q_star_wong_parker"].get<double>(), j["q_star_nielsen"].get<double>());
  return exit_code;
}

namespace {

/// A bed on the wall y = 0 under gravity along -y, below a slip (mirror) top, as the paper's.
void sediment_transport_checks(const CaseParams& p, SceneFindings& f) {
  if (std::abs(std::cos(p.gravity.angle_deg * kPi / 180.0) - 1.0) > 1e-9)
    f.errors.push_back(fmt::format(
        "gravity.angle_deg = {} for sediment_transport: must be 0 (gravity along -y)", p.gravity.angle_deg));
  if (p.domain.periodic_y)
    f.errors.push_back(
        "domain.periodic_y = true for sediment_transport: must be false (a bed on the wall y = 0)");
  const double h_bed = bed_height_m(p, static_cast<double>(p.particles.count) * p.particle_volume_m3());
  if (h_bed >= p.domain.width_y_m)
    f.errors.push_back(fmt::format("bed height {:.4g} m fills the channel: must be < domain.width_y = {} m",
                                   h_bed, p.domain.width_y_m));
  if (p.domain.top_wall != "slip")
    f.warnings.push_back(
        fmt::format("domain.top_wall = \"{}\" for sediment_transport: the paper's top is a slip "
                    "(mirror) wall; the Shields stress assumes it",
                    p.domain.top_wall));
}

/// The coupled run's keys, but of time and output only those it uses: time.target_rel_error is
/// <<w_p>>'s (inclined_settling), not this scene's.
std::vector<std::string> sediment_transport_keys() {
  auto keys = coupled_scene_keys();
  std::erase(keys, std::string("time."));
  for (const char* k :
       {"time.dt_cfd", "time.dt_dem", "time.end", "time.average_from", "time.checkpoint_every", "sediment.",
        "output.timeseries_every", "output.keep_checkpoints", "output.snapshot_times", "output.image_times"})
    keys.emplace_back(k);
  return keys;
}

}  // namespace

const SceneRegistration kRegistered{
    {.name = "sediment_transport",
     .measures = "q* against the Shields stress tau*, beside Wong-Parker and Nielsen; profiles over y",
     .reads = sediment_transport_keys(),
     .defaults = {{"gravity.angle_deg", "0.0"},
                  {"domain.top_wall", "\"slip\""},
                  {"particles.insertion", "\"bed\""}},
     .default_solid_fraction = table3_solid_fraction(),
     .own_checks = &sediment_transport_checks},
    &run_sediment_transport};

}  // namespace boycott::scenes
