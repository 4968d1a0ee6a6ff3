#pragma once
// The case: one plain struct of parameters with Table III defaults (Zeng et al. 2021), units in
// the names. Parsed, overridden, validated, serialised and hashed in one place (case_params.cpp);
// every key appears once in the key table there, so adding a key means editing that table only.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace boycott {

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
inline bool is_set(double v) {
  return !std::isnan(v);
}

struct FluidParams {
  double density_kg_m3 = 1000.0;
  double viscosity_pa_s = 1.0e-3;        ///< dynamic viscosity
  std::string subgrid_model = "vreman";  ///< "vreman" | "none"
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
  double restitution = 0.1;       ///< e, sets gamma_n (design brief section 2)
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
  std::string top_wall = "no_slip";  ///< fluid condition at y = W: "no_slip" | "slip"
};

struct GravityParams {
  double angle_deg = 65.0;  ///< theta; g = (0, -g cos theta, -g sin theta)
  double magnitude_m_s2 = 9.81;
};

struct TimeParams {
  double dt_cfd_s = 1.0e-3;  ///< upper bound; the CFL limit may lower it
  double dt_dem_s = 2.0e-5;
  double end_s = 20.0;
  double average_from_s = 5.0;
  double checkpoint_every_s = 1.0;  ///< simulated seconds
};

struct ForceParams {
  std::string drag = "difelice_paper";  ///< "difelice_paper" | "schiller_naumann" | "stokes" | "none"
  bool saffman_lift = true;
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
  double pressure_relaxation = 0.5;
  /// "simple" (the paper's, iterated to simple_tolerance) or "piso" (Issa 1986: one momentum
  /// solve and piso_correctors pressure corrections per step, not iterated; faster, its
  /// difference from SIMPLE is reported in the README).
  std::string pressure_velocity_coupling = "simple";
  std::int64_t piso_correctors = 2;
  double cfl_max = 0.5;
  double neighbor_skin_m = 0.3e-3;
  std::string void_fraction_kernel = "trilinear_smoothed";
};

struct OutputParams {
  double timeseries_every_s = kUnset;  ///< unset: every CFD step
  std::int64_t keep_checkpoints = 3;
  std::vector<double> snapshot_times_s;
  std::vector<double> image_times_s;
  std::int64_t pdf_bins = 40;
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

/// The scenes that exist; validate() refuses any other name.
const std::vector<std::string>& scene_names();

/// Parses a case file. Unknown keys, wrong types and out-of-range values are InputErrors naming
/// the key, the value and the limit.
CaseParams parse_case_file(const std::string& path);
CaseParams parse_case_string(const std::string& toml_text, const std::string& origin = "<string>");
/// Parses from JSON (the canonical form written beside every run).
CaseParams case_from_json(const nlohmann::json& j);

/// Applies "section.key=value" (value in TOML syntax: 1e-3, true, "vreman", [1,2,3]).
void apply_override(CaseParams& p, const std::string& assignment);

/// Resolves derived inputs (volume_fraction -> count) and checks every limit, per key and
/// across keys (d < W, Delta t_DEM <= spring limit, count fits the box, ...). Throws InputError.
void validate(CaseParams& p);

/// Canonical JSON: every key, sorted, defaults included. Equal parameters give equal text.
nlohmann::json to_json(const CaseParams& p);
/// Hash of the canonical JSON, 16 hex digits: the case's identity.
std::string case_id(const CaseParams& p);

/// All dotted key names in table order (for documentation and `case keys`).
std::vector<std::string> case_key_names();

}  // namespace boycott
