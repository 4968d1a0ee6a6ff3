#pragma once
// The table of case keys: every key once, with the member it sets (its type, and its default as
// the member's initializer in case_params.hpp), its limits and unit, and its one line of meaning.
// Internal to boycott_core: parsing (case_parse.cpp), checking (case_rules.cpp), identity
// (case_params.cpp) and the documentation of `case keys` (key_docs.cpp) all walk this one list.
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/model_names.hpp"

namespace boycott::case_keys {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Per-key limits: a numeric interval (applied to every element of an array) or a set of names.
struct Rule {
  double min = -kInf;
  double max = kInf;
  bool min_open = false;
  bool max_open = false;
  std::vector<std::string> choices;
  const char* unit = "";
  bool optional = false;  ///< may be unset (NaN)
  const char* doc = "";   ///< one line of meaning (`case keys`); a name key's choices are appended
};

inline Rule positive(const char* unit) {
  return Rule{0.0, kInf, true, false, {}, unit};
}
inline Rule nonneg(const char* unit) {
  return Rule{0.0, kInf, false, false, {}, unit};
}
inline Rule range(double a, double b, const char* unit = "") {
  return Rule{a, b, false, false, {}, unit};
}
inline Rule open_range(double a, double b, bool lo_open, bool hi_open, const char* unit = "") {
  return Rule{a, b, lo_open, hi_open, {}, unit};
}
inline Rule any(const char* unit = "") {
  return Rule{-kInf, kInf, false, false, {}, unit};
}
inline Rule optional(Rule r) {
  r.optional = true;
  return r;
}
inline Rule choice(std::vector<std::string> c) {
  Rule r;
  r.choices = std::move(c);
  return r;
}

/// The key table. Every case key is listed here exactly once: its name, the member it sets, its
/// limits and its meaning. `visitor` is called as visitor(name, member, rule), rule.doc set.
template <class P, class V>
void visit_keys(P& p, V&& visitor) {
  const auto v = [&](const char* key, auto& member, Rule rule, const char* doc) {
    rule.doc = doc;
    visitor(key, member, rule);
  };
  v("scene", p.scene, choice(scene_names()),
    "what is simulated and measured (see the scene table of the README)");
  v("seed", p.seed, range(0, 9.0e18), "random seed of particle insertion and of the initial perturbations");

  v("fluid.density", p.fluid.density_kg_m3, positive("kg/m^3"), "fluid density rho_f");
  v("fluid.viscosity", p.fluid.viscosity_pa_s, positive("Pa s"), "dynamic viscosity mu_f");
  v("fluid.subgrid_model", p.fluid.subgrid_model, choice(subgrid_model_names()),
    "LES subgrid model (vreman is the paper's)");

  v("particles.diameter", p.particles.diameter_m, positive("m"), "particle diameter d");
  v("particles.density", p.particles.density_kg_m3, positive("kg/m^3"), "particle density rho_p");
  v("particles.count", p.particles.count, range(0, 1.0e9), "number of particles (or give volume_fraction)");
  v("particles.volume_fraction", p.particles.volume_fraction, optional(open_range(0.0, 0.64, false, false)),
    "solid fraction alpha_p of the box; overrides count");
  v("particles.insertion", p.particles.insertion, choice({"random", "bed", "packed"}),
    "how particles are placed (random: uniform in the box; bed: settled from y = 0 before the run; packed: "
    "grown in place)");

  v("contact.stiffness", p.contact.stiffness_n_m, positive("N/m"),
    "normal and tangential spring stiffness k_n = k_t");
  v("contact.restitution", p.contact.restitution, open_range(0.0, 1.0, true, false),
    "coefficient of restitution e (sets the normal damping)");
  v("contact.friction", p.contact.friction, nonneg(""),
    "sliding friction coefficient mu_s (Coulomb cap, Eq. 10)");
  v("contact.rolling_friction", p.contact.rolling_friction, nonneg(""),
    "rolling friction coefficient mu_r (Eq. 11)");
  v("contact.tangential_damping_ratio", p.contact.tangential_damping_ratio, range(0.0, 1.0),
    "gamma_t / gamma_n");
  v("contact.model", p.contact.model, choice(contact_model_names()), "contact force law");
  v("contact.rolling_model", p.contact.rolling_model, choice(rolling_model_names()),
    "rolling resistance model");
  v("contact.clip_attractive_normal", p.contact.clip_attractive_normal, any(),
    "true: the normal force never turns attractive");

  v("domain.length_x", p.domain.length_x_m, positive("m"),
    "box length along x (periodic, along the channel)");
  v("domain.width_y", p.domain.width_y_m, positive("m"), "gap between the walls at y = 0 and y = W");
  v("domain.height_z", p.domain.height_z_m, positive("m"),
    "box height along z (periodic, settling direction)");
  v("domain.cells", p.domain.cells, range(1, 4096), "fluid cells [nx, ny, nz]");
  v("domain.periodic_y", p.domain.periodic_y, any(), "true: periodic in y instead of walls");
  v("domain.top_wall", p.domain.top_wall, choice({"no_slip", "slip"}), "fluid condition at y = W");

  v("gravity.angle_deg", p.gravity.angle_deg, range(0.0, 90.0, "deg"),
    "inclination theta from the horizontal; 90 is vertical");
  v("gravity.magnitude", p.gravity.magnitude_m_s2, nonneg("m/s^2"),
    "magnitude of the gravitational acceleration");

  v("time.dt_cfd", p.time.dt_cfd_s, positive("s"),
    "fluid time step (upper bound; the CFL limit may lower it)");
  v("time.dt_dem", p.time.dt_dem_s, positive("s"), "particle time step");
  v("time.end", p.time.end_s, positive("s"),
    "simulated time at which the run ends (raise it to continue a run)");
  v("time.average_from", p.time.average_from, nonneg("s"),
    "start of the averaging window of <<w_p>>, or \"auto\": where its start-up transient ends");
  v("time.checkpoint_every", p.time.checkpoint_every_s, positive("s"),
    "simulated time between restart checkpoints");
  v("time.target_rel_error", p.time.target_rel_error, optional(open_range(0.0, 1.0, true, true)),
    "stop once the relative error of <<w_p>> is below this");

  v("forces.drag", p.forces.drag, choice(drag_law_names()),
    "drag law (difelice_paper: Eqs. 13-15 as the paper prints them)");
  v("forces.saffman_lift", p.forces.saffman_lift, any(), "shear lift on or off (off: forces.lift = none)");
  v("forces.lift", p.forces.lift, choice(lift_law_names()),
    "shear lift law (saffman: Eq. 16; saffman_mei: Mei's 1992 finite-Re factor; saffman_mei_continuous: "
    "the same without its jump at Re_p = 40; mclaughlin: McLaughlin's 1991 J(epsilon) / J(inf))");
  v("forces.added_mass", p.forces.added_mass, any(), "added-mass force on or off");
  v("forces.pressure_gradient", p.forces.pressure_gradient, any(), "pressure-gradient force on or off");
  v("forces.viscous", p.forces.viscous, any(), "viscous-stress (divergence of tau) force on or off");

  v("flow.body_acceleration", p.flow.body_acceleration_m_s2, any("m/s^2"),
    "body acceleration [x, y, z] driving the fluid");
  v("flow.target_mean_velocity_z", p.flow.target_mean_velocity_z_m_s, optional(any("m/s")),
    "mean z-velocity held by a flux controller (unset: off)");

  v("numerics.simple_max_iterations", p.numerics.simple_max_iterations, range(1, 10000),
    "SIMPLE iterations per fluid step at most");
  v("numerics.simple_tolerance", p.numerics.simple_tolerance, open_range(0.0, 1.0, true, false),
    "relative change of the continuity residual ending SIMPLE");
  v("numerics.velocity_relaxation", p.numerics.velocity_relaxation, open_range(0.0, 1.0, true, false),
    "under-relaxation of velocity (SIMPLE only)");
  v("numerics.pressure_relaxation", p.numerics.pressure_relaxation, open_range(0.0, 1.0, true, false),
    "takes only its default: SIMPLEC applies the pressure correction whole");
  v("numerics.pressure_velocity_coupling", p.numerics.pressure_velocity_coupling, choice({"simple", "piso"}),
    "pressure-velocity coupling (simple is the paper's)");
  v("numerics.piso_correctors", p.numerics.piso_correctors, range(1, 100),
    "pressure corrections per PISO step");
  v("numerics.simple_correctors", p.numerics.simple_correctors, range(1, 100),
    "pressure corrections per SIMPLE iteration");
  v("numerics.cfl_max", p.numerics.cfl_max, open_range(0.0, 1.0, true, false),
    "largest Courant number; lowers dt_cfd when exceeded");
  v("numerics.neighbor_skin", p.numerics.neighbor_skin_m, positive("m"),
    "Verlet skin of the contact neighbour lists");
  v("numerics.void_fraction_kernel", p.numerics.void_fraction_kernel, choice(kernel_names()),
    "deposition kernel of particle volume and forces");
  v("numerics.sampling", p.numerics.sampling, choice(sampling_names()),
    "how the fluid is read at the particles (trilinear: from each field's own nodes, wall rules)");
  v("numerics.vorticity", p.numerics.vorticity, choice(vorticity_names()),
    "where the lift's vorticity is formed (cell_centres: 2-cell central; edges: compact)");
  v("numerics.drag_dt_limit", p.numerics.drag_dt_limit, any(),
    "lower dt_cfd where packed particles would relax past the fluid's lagged counterflow");

  v("output.timeseries_every", p.output.timeseries_every_s, optional(positive("s")),
    "simulated time between rows of timeseries.csv (unset: every step)");
  v("output.keep_checkpoints", p.output.keep_checkpoints, range(1, 1000), "newest checkpoints kept");
  v("output.snapshot_times", p.output.snapshot_times_s, nonneg("s"),
    "times of XDMF/HDF5 snapshots of particles and fluid");
  v("output.image_times", p.output.image_times_s, nonneg("s"), "times of PNG images of the particles");
  v("output.pdf_bins", p.output.pdf_bins, range(2, 100000), "bins of the PDFs of y and w_p");
  v("output.force_budget_y", p.output.force_budget_y, any(),
    "write force_budget_y.csv: each force on the particles per band of y");
  v("output.velocity_profile_y", p.output.velocity_profile_y, any(),
    "write velocity_profile_y.csv: particle and seen fluid velocities, slip and flux share per band of y");

  v("ergun.pressure_gradients", p.ergun.pressure_gradients_pa_m, positive("Pa/m"),
    "driving pressure gradients swept over the frozen bed");
  v("sediment.bulk_velocity", p.sediment.bulk_velocity_m_s, any("m/s"),
    "target z-averaged bulk velocity of the flow over the bed");
  v("sediment.bed_height", p.sediment.bed_height_m, optional(positive("m")),
    "bed height (unset: from the particle count)");
  v("sediment.initial_flow", p.sediment.initial_flow, choice({"turbulent", "rest"}),
    "fluid at t = 0 (turbulent: log law, perturbed; rest: still)");
}

/// Keys added after identity version 2, each with the value that reproduces the behaviour
/// before it existed: the key enters a case's id only when its value differs from that, so
/// adding a key never changes the id of a case that does not use it; and a stored case (JSON of
/// an earlier build) that lacks it had that behaviour, whatever the default is now. Append every
/// new key here.
struct LateKey {
  const char* key;
  const char* old_behaviour;  ///< the value as JSON text (valid TOML too)
};
inline constexpr std::array<LateKey, 5> kLateKeys{{{"numerics.sampling", "\"kernel\""},
                                                   {"numerics.simple_correctors", "1"},
                                                   {"forces.lift", "\"saffman\""},
                                                   {"numerics.vorticity", "\"cell_centres\""},
                                                   {"numerics.drag_dt_limit", "false"}}};

/// Sets one key from its TOML text (a bare word is a string); false for an unknown key
/// (case_parse.cpp).
bool set_key(CaseParams& p, const std::string& key, const std::string& value);
/// Whether the user set the key (case file or --set), rather than it taking its default.
bool is_set_key(const CaseParams& p, const std::string& key);
/// "a.b" as the JSON pointer "/a/b".
nlohmann::json::json_pointer pointer_of(const std::string& dotted);
/// A number as the messages print it.
std::string fmt_num(double v);

}  // namespace boycott::case_keys
