#pragma once
// The case: one plain struct of parameters with Table III defaults (Zeng et al. 2021), units in
// the names; a member's initializer is its key's default. Every key appears once in the key table
// (case_key_table.hpp: name, member, limits, unit, meaning, and for a name its choices from
// model_names.hpp), which parsing and overrides (case_parse.cpp), validation (case_rules.cpp),
// serialisation and the case id (case_params.cpp) and `case keys` (key_docs.cpp) all read: adding
// a key means a member here and a line in that table.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene_specs.hpp"

namespace boycott {

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
inline bool is_set(double v) {
  return !std::isnan(v);
}

struct FluidParams {
  double density_kg_m3 = 1000.0;
  double viscosity_pa_s = 1.0e-3;  ///< dynamic viscosity
  std::string subgrid_model = "vreman";
};

struct ParticleParams {
  double diameter_m = 0.6e-3;
  double density_kg_m3 = 2650.0;
  std::int64_t count = 120000;
  /// When set, overrides `count`: count = round(volume_fraction * V_box / V_p).
  double volume_fraction = kUnset;
  /// "random": uniform non-overlapping in the whole box; "bed": random packing settled from the
  /// bottom (y = 0) by the scene before the measured run.
  std::string insertion = "random";
};

struct ContactParams {
  double stiffness_n_m = 3.5;     ///< k_n = k_t
  double restitution = 0.1;       ///< e, sets gamma_n (docs/model.md)
  double friction = 0.6;          ///< mu_s, Coulomb cap (Eq. 10)
  double rolling_friction = 0.1;  ///< mu_r (Eq. 11)
  /// gamma_t / gamma_n (the paper leaves gamma_t open; LIGGGHTS' deck of the bench uses 1/2).
  double tangential_damping_ratio = 0.5;
  std::string model = "linear_spring_dashpot";
  std::string rolling_model = "constant_directional";  ///< or "none"
  /// true: the normal force never turns attractive (restitution then exceeds e, see tests).
  bool clip_attractive_normal = false;
};

struct DomainParams {
  double length_x_m = 0.2;                            ///< periodic
  double width_y_m = 0.006;                           ///< walls at y = 0 and y = W unless periodic_y
  double height_z_m = 0.1;                            ///< periodic, settling direction
  std::array<std::int64_t, 3> cells = {200, 6, 100};  ///< x, y, z
  bool periodic_y = false;
  std::string top_wall = "no_slip";  ///< fluid condition at y = W
};

struct GravityParams {
  double angle_deg = 65.0;  ///< theta; g = (0, -g cos theta, -g sin theta)
  double magnitude_m_s2 = 9.81;
};

/// Where <<w_p>>'s averaging window starts: a time, or "auto" (`automatic`): where the run's
/// start-up transient is detected to end, judged from its whole per-step series when it ends
/// (inclined_settling alone keeps that series).
struct WindowStart {
  double time_s = 5.0;
  bool automatic = false;
  /// The time from which a run collects its window's samples: all of the run when automatic.
  double collect_from_s() const { return automatic ? 0.0 : time_s; }
  bool operator==(const WindowStart&) const = default;
};

struct TimeParams {
  double dt_cfd_s = 1.0e-3;  ///< upper bound; the CFL limit may lower it
  double dt_dem_s = 2.0e-5;
  double end_s = 20.0;
  WindowStart average_from;
  double checkpoint_every_s = 1.0;  ///< simulated seconds
  /// Stop once the relative standard error of <<w_p>> is below this (unset: run to end_s).
  double target_rel_error = kUnset;
};

struct ForceParams {
  std::string drag = "difelice_paper";
  bool saffman_lift = true;
  /// The shear lift law while saffman_lift is on (coupling/lift_laws.hpp); saffman_lift = false
  /// means "none". Mei's by default: at the Re_p of 20-50 of these suspensions Saffman's law is outside its
  /// validity (Re_p << Re_w^1/2 << 1) and imprints the grid on the particles (docs/validation.md,
  /// "Across the gap"). Cases of earlier builds ran "saffman" and keep their ids.
  std::string lift = "saffman_mei";
  bool added_mass = true;
  bool pressure_gradient = true;
  bool viscous = true;
};

struct FlowParams {
  std::array<double, 3> body_acceleration_m_s2 = {0.0, 0.0, 0.0};
  double target_mean_velocity_z_m_s = kUnset;  ///< flux controller target; unset = off
};

struct NumericsParams {
  std::int64_t simple_max_iterations = 30;
  double simple_tolerance = 1.0e-6;  ///< relative change of the continuity residual
  /// 1 (none): with dt bounded by CFL 0.5 the BDF2 term c0 alpha / dt dominates the momentum
  /// diagonal, so under-relaxation only slows SIMPLE (8.5 -> 5 iterations per step on the bench
  /// mesh at 0.8) and moves the converged step by less than simple_tolerance.
  double velocity_relaxation = 1.0;  ///< SIMPLE only
  /// Only this value is accepted: SIMPLEC applies its pressure correction whole (case_rules.cpp).
  double pressure_relaxation = 0.5;
  /// "simple" (the paper's, iterated to simple_tolerance) or "piso" (Issa 1986: one momentum
  /// solve and piso_correctors pressure corrections per step, not iterated; faster, its
  /// difference from SIMPLE is reported in the README).
  std::string pressure_velocity_coupling = "simple";
  std::int64_t piso_correctors = 2;
  /// Pressure corrections per SIMPLE iteration. Beyond the first, each moves the velocity by a
  /// sweep of the momentum equations at the corrected pressure and corrects again (the PISO
  /// corrector inside the iteration): the converged step meets the same simple_tolerance, in
  /// fewer iterations where convection is strong (docs/model.md).
  std::int64_t simple_correctors = 2;
  double cfl_max = 0.5;
  double neighbor_skin_m = 0.3e-3;
  std::string void_fraction_kernel = "trilinear_smoothed";
  /// How the fluid is read at the particles: "kernel" (the deposition kernel's weights, the
  /// first round's way) or "trilinear" (each field from its own staggered nodes with its wall
  /// rule; coupling/sampling.hpp).
  std::string sampling = "kernel";
  /// Where the vorticity (the lift's shear) is formed: "cell_centres" (central differences of
  /// cell-centred velocities over two cells, blind to a profile that alternates cell by cell) or
  /// "edges" (compact differences at the staggered grid's edges, read from there).
  std::string vorticity = "cell_centres";
  /// Bound dt_cfd by the stability of the explicit particle-fluid exchange where particles are
  /// packed (alpha_f < 1/2): coupling/drag_stability.hpp. Off, a packed bed in a viscous fluid
  /// (10 cP, 0.6 mm sand at dt_cfd 1 ms) oscillates step by step until alpha_f leaves (0, 1].
  bool drag_dt_limit = true;
};

struct OutputParams {
  double timeseries_every_s = kUnset;  ///< unset: every CFD step
  std::int64_t keep_checkpoints = 3;
  std::vector<double> snapshot_times_s;
  std::vector<double> image_times_s;
  std::int64_t pdf_bins = 40;
  /// Write force_budget_y.csv: every force on the particles per band of y over the averaging
  /// window (coupling/force_budget.hpp), in pdf_bins bands.
  bool force_budget_y = false;
  /// Write velocity_profile_y.csv: the particles' mean velocities, the fluid velocity they see,
  /// their slip and their share of the flux per band of y over the averaging window
  /// (coupling/velocity_profile.hpp), in pdf_bins bands.
  bool velocity_profile_y = false;
};

struct ErgunParams {
  /// Driving pressure gradients swept over the frozen bed, Pa/m.
  std::vector<double> pressure_gradients_pa_m = {1.0e2, 1.0e3, 1.0e4, 5.0e4, 2.0e5};
};

struct SedimentParams {
  double bulk_velocity_m_s = 0.8;  ///< target z-averaged bulk velocity
  double bed_height_m = kUnset;    ///< unset: from the particle count
  /// Fluid at t = 0: "turbulent", a log-law profile over the bed top at the bulk velocity with
  /// large-scale random perturbations of 5 % of it per mode (the flow is turbulent within
  /// ~0.5 s); or "rest", an impulsive start from still fluid, whose first step kicks the bed with
  /// the whole acceleration (see the README: the flow then relaminarises or the bed is blown
  /// into suspension, depending on the plan).
  std::string initial_flow = "turbulent";
};

struct CaseParams {
  std::string scene = "inclined_settling";
  std::int64_t seed = 1;
  FluidParams fluid;
  ParticleParams particles;
  ContactParams contact;
  DomainParams domain;
  GravityParams gravity;
  TimeParams time;
  ForceParams forces;
  FlowParams flow;
  NumericsParams numerics;
  OutputParams output;
  ErgunParams ergun;
  SedimentParams sediment;

  /// A run branched from another run's checkpoint (`case run --from`): the parent case and the
  /// time it starts from. Part of the identity (the same physics from another state is another
  /// case), never a key of a case file.
  struct Branch {
    std::string parent_id;
    double parent_time_s = kUnset;
  } branch;

  // ---- provenance (not part of the case's values) ----
  /// Keys the user set (case file, --set, a study's base, group and matrix), sorted: the only
  /// ones a scene may refuse, and the ones its defaults do not replace.
  std::vector<std::string> set_keys;
  /// validate() has applied the scene's defaults and derived the particle count and skin; a
  /// case read back from its canonical JSON is resolved already.
  bool resolved = false;

  // ---- derived quantities (from the resolved parameters) ----
  double particle_volume_m3() const;
  double particle_mass_kg() const;
  double box_volume_m3() const;
  /// alpha_p = N V_p / V_box
  double solid_fraction() const;
  /// Gravity vector (0, -g cos theta, -g sin theta), m/s^2.
  std::array<double, 3> gravity_vector() const;
  /// DEM step bound (pi/5) sqrt(m/k_n), s.
  double dem_spring_limit_s() const;
  /// Number of DEM sub-steps per CFD step.
  std::int64_t dem_substeps() const;
};

/// Parses a case file. Unknown keys, wrong types and out-of-range values are InputErrors naming
/// the key, the value and the limit.
CaseParams parse_case_file(const std::string& path);
/// `name_lines`: an error in a key's value begins "origin:line: " (off where the text is not
/// the user's own, as a study's [base] written back as TOML).
CaseParams parse_case_string(const std::string& toml_text, const std::string& origin = "<string>",
                             bool name_lines = true);
/// A case file with its --set overrides, validated; an error in a value the file sets names the
/// file and line ("case.toml:12: fluid.viscosity = -1 is out of range: ..."). A file named
/// *.json is a case in its canonical JSON (a run's params.json, the case.json a study writes for
/// its solver): checked as it is (nothing resolved again: a --set changes that one value, and
/// particles.volume_fraction, which only derives the count, is refused), unknown keys refused.
CaseParams load_case_file(const std::string& path, const std::vector<std::string>& overrides);
/// "origin:line: " of the line of `toml_text` that sets the dotted `key`; "" where none does.
std::string case_key_location(const std::string& toml_text, const std::string& origin,
                              const std::string& key);
/// Parses from JSON (the canonical form written beside every run).
CaseParams case_from_json(const nlohmann::json& j);

/// Applies "section.key=value" (value in TOML syntax: 1e-3, true, "vreman", [1,2,3]).
/// Returns the key it set.
std::string apply_override(CaseParams& p, const std::string& assignment);

/// Refuses a user-set key the scene does not read (naming the key and the scene), applies the
/// scene's defaults to the keys the user did not set, derives the particle count (from
/// particles.volume_fraction, or the scene's default solid fraction in the case's own box) and
/// the neighbour skin (min(0.3 mm, d)), and checks every limit, per key and across keys (d < W,
/// Delta t_DEM <= spring limit, count fits the box, ...). Throws InputError.
void validate(CaseParams& p);

/// Canonical JSON of a resolved case: the scene and the keys it reads, sorted, defaults
/// included. Equal cases give equal text. (params.json in every run folder.)
nlohmann::json to_json(const CaseParams& p);
/// Every key of the key table, whichever scene (for `case keys`).
nlohmann::json to_json_all_keys(const CaseParams& p);
/// The identity scheme case_id() follows (stored with results, so a database knows its ids).
inline constexpr int kCaseIdVersion = 2;
/// The case's identity, 16 hex digits: the hash of the physics keys its scene reads at their
/// resolved values, with the scheme's version. Keys that only steer output or the run's length
/// (time.end, time.checkpoint_every, time.target_rel_error, output.*) are not part of it, so
/// raising time.end continues a finished run; a key added after version 2 enters it only where
/// its value differs from the behaviour before the key existed.
std::string case_id(const CaseParams& p);
/// The identity of a case stored as canonical JSON (params.json, a checkpoint's case_json), in
/// this program's scheme whatever scheme it was written under.
std::string case_id_of_json(const std::string& canonical_json);
/// The keys case_id() leaves out because they steer output or the run's length only.
bool is_output_only_key(const std::string& key);

/// All dotted key names in table order (for documentation and `case keys`).
std::vector<std::string> case_key_names();
/// The dotted key names a scene reads, in table order.
std::vector<std::string> case_key_names(const std::string& scene);

}  // namespace boycott
