#pragma once
// The table of case keys (solver/core/case_params.cpp and the files beside it read it): every
// key once, with the member it sets and its limits. Internal to boycott_core: parsing
// (case_parse.cpp), checking (case_rules.cpp) and identity (case_params.cpp) all walk this one list.
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

/// The key table. Every case key is listed here exactly once, with its member and its limits.
template <class P, class V>
void visit_keys(P& p, V&& v) {
  v("scene", p.scene, choice(scene_names()));
  v("seed", p.seed, range(0, 9.0e18));

  v("fluid.density", p.fluid.density_kg_m3, positive("kg/m^3"));
  v("fluid.viscosity", p.fluid.viscosity_pa_s, positive("Pa s"));
  v("fluid.subgrid_model", p.fluid.subgrid_model, choice(subgrid_model_names()));

  v("particles.diameter", p.particles.diameter_m, positive("m"));
  v("particles.density", p.particles.density_kg_m3, positive("kg/m^3"));
  v("particles.count", p.particles.count, range(0, 1.0e9));
  v("particles.volume_fraction", p.particles.volume_fraction, optional(open_range(0.0, 0.64, false, false)));
  v("particles.insertion", p.particles.insertion, choice({"random", "bed", "packed"}));

  v("contact.stiffness", p.contact.stiffness_n_m, positive("N/m"));
  v("contact.restitution", p.contact.restitution, open_range(0.0, 1.0, true, false));
  v("contact.friction", p.contact.friction, nonneg(""));
  v("contact.rolling_friction", p.contact.rolling_friction, nonneg(""));
  v("contact.tangential_damping_ratio", p.contact.tangential_damping_ratio, range(0.0, 1.0));
  v("contact.model", p.contact.model, choice(contact_model_names()));
  v("contact.rolling_model", p.contact.rolling_model, choice(rolling_model_names()));
  v("contact.clip_attractive_normal", p.contact.clip_attractive_normal, any());

  v("domain.length_x", p.domain.length_x_m, positive("m"));
  v("domain.width_y", p.domain.width_y_m, positive("m"));
  v("domain.height_z", p.domain.height_z_m, positive("m"));
  v("domain.cells", p.domain.cells, range(1, 4096));
  v("domain.periodic_y", p.domain.periodic_y, any());
  v("domain.top_wall", p.domain.top_wall, choice({"no_slip", "slip"}));

  v("gravity.angle_deg", p.gravity.angle_deg, range(0.0, 90.0, "deg"));
  v("gravity.magnitude", p.gravity.magnitude_m_s2, nonneg("m/s^2"));

  v("time.dt_cfd", p.time.dt_cfd_s, positive("s"));
  v("time.dt_dem", p.time.dt_dem_s, positive("s"));
  v("time.end", p.time.end_s, positive("s"));
  v("time.average_from", p.time.average_from, nonneg("s"));
  v("time.checkpoint_every", p.time.checkpoint_every_s, positive("s"));
  v("time.target_rel_error", p.time.target_rel_error, optional(open_range(0.0, 1.0, true, true)));

  v("forces.drag", p.forces.drag, choice(drag_law_names()));
  v("forces.saffman_lift", p.forces.saffman_lift, any());
  v("forces.lift", p.forces.lift, choice(lift_law_names()));
  v("forces.added_mass", p.forces.added_mass, any());
  v("forces.pressure_gradient", p.forces.pressure_gradient, any());
  v("forces.viscous", p.forces.viscous, any());

  v("flow.body_acceleration", p.flow.body_acceleration_m_s2, any("m/s^2"));
  v("flow.target_mean_velocity_z", p.flow.target_mean_velocity_z_m_s, optional(any("m/s")));

  v("numerics.simple_max_iterations", p.numerics.simple_max_iterations, range(1, 10000));
  v("numerics.simple_tolerance", p.numerics.simple_tolerance, open_range(0.0, 1.0, true, false));
  v("numerics.velocity_relaxation", p.numerics.velocity_relaxation, open_range(0.0, 1.0, true, false));
  v("numerics.pressure_relaxation", p.numerics.pressure_relaxation, open_range(0.0, 1.0, true, false));
  v("numerics.pressure_velocity_coupling", p.numerics.pressure_velocity_coupling, choice({"simple", "piso"}));
  v("numerics.piso_correctors", p.numerics.piso_correctors, range(1, 100));
  v("numerics.simple_correctors", p.numerics.simple_correctors, range(1, 100));
  v("numerics.cfl_max", p.numerics.cfl_max, open_range(0.0, 1.0, true, false));
  v("numerics.neighbor_skin", p.numerics.neighbor_skin_m, positive("m"));
  v("numerics.void_fraction_kernel", p.numerics.void_fraction_kernel, choice(kernel_names()));
  v("numerics.sampling", p.numerics.sampling, choice(sampling_names()));
  v("numerics.vorticity", p.numerics.vorticity, choice(vorticity_names()));

  v("output.timeseries_every", p.output.timeseries_every_s, optional(positive("s")));
  v("output.keep_checkpoints", p.output.keep_checkpoints, range(1, 1000));
  v("output.snapshot_times", p.output.snapshot_times_s, nonneg("s"));
  v("output.image_times", p.output.image_times_s, nonneg("s"));
  v("output.pdf_bins", p.output.pdf_bins, range(2, 100000));
  v("output.force_budget_y", p.output.force_budget_y, any());

  v("ergun.pressure_gradients", p.ergun.pressure_gradients_pa_m, positive("Pa/m"));
  v("sediment.bulk_velocity", p.sediment.bulk_velocity_m_s, any("m/s"));
  v("sediment.bed_height", p.sediment.bed_height_m, optional(positive("m")));
  v("sediment.initial_flow", p.sediment.initial_flow, choice({"turbulent", "rest"}));
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
inline constexpr std::array<LateKey, 4> kLateKeys{{{"numerics.sampling", "\"kernel\""},
                                                   {"numerics.simple_correctors", "1"},
                                                   {"forces.lift", "\"saffman\""},
                                                   {"numerics.vorticity", "\"cell_centres\""}}};

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
