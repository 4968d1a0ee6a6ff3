#include "core/scene_specs.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/constants.hpp"
#include "core/error.hpp"

namespace boycott {

double table3_solid_fraction() {
  const double d = 0.6e-3, vp = kPi / 6.0 * d * d * d;
  return 120000.0 * vp / (0.2 * 0.006 * 0.1);
}

namespace {

std::vector<SceneSpec> make_specs() {
  const double a3 = table3_solid_fraction();
  // The keys of a coupled CFD-DEM run: the fluid (its forcing is the scene's own), the
  // particles, their contacts and the fluid forces on them, the time steps and the numerics.
  const std::vector<std::string> coupled = {"seed",     "fluid.", "particles.", "contact.", "domain.",
                                            "gravity.", "time.",  "forces.",    "numerics."};
  auto with = [](std::vector<std::string> a, std::initializer_list<const char*> more) {
    for (const char* k : more) a.emplace_back(k);
    return a;
  };
  auto without = [](std::vector<std::string> a, const char* key) {
    std::erase(a, std::string(key));
    return a;
  };
  std::vector<SceneSpec> s;
  s.push_back({"inclined_settling",
               "<<w_p>> over [average_from, end] with its error, <w_p>(t), PDFs of y and w_p, images",
               with(coupled, {"output."}),
               {},
               true,
               a3});
  s.push_back(
      {"sediment_transport",
       "q* against the Shields stress tau*, beside Wong-Parker and Nielsen; profiles over y",
       // time.target_rel_error is <<w_p>>'s (inclined_settling): not this scene's.
       with(without(coupled, "time."),
            {"time.dt_cfd", "time.dt_dem", "time.end", "time.average_from", "time.checkpoint_every",
             "sediment.", "output.timeseries_every", "output.keep_checkpoints", "output.snapshot_times",
             "output.image_times"}),
       {{"gravity.angle_deg", "0.0"}, {"domain.top_wall", "\"slip\""}, {"particles.insertion", "\"bed\""}},
       true,
       a3});
  s.push_back(
      {"single_particle",
       "terminal velocity of one sphere against the drag law's",
       {"fluid.", "particles.diameter", "particles.density", "contact.", "domain.", "gravity.", "time.dt_cfd",
        "time.dt_dem", "time.end", "time.average_from", "time.checkpoint_every", "forces.", "numerics.",
        "output.timeseries_every", "output.keep_checkpoints", "output.snapshot_times", "output.image_times"},
       {},
       false,
       0.0});
  s.push_back({"ergun",
               "f* against Re*_p through a packed, frozen bed, beside the Ergun equation",
               {"seed", "fluid.", "particles.", "contact.", "domain.", "time.dt_cfd", "time.dt_dem",
                "forces.", "numerics.", "ergun."},
               {{"domain.periodic_y", "true"},
                {"particles.insertion", "\"packed\""},
                {"fluid.subgrid_model", "\"none\""},
                {"forces.saffman_lift", "false"},
                {"forces.added_mass", "false"}},
               true,
               0.64});
  s.push_back({"channel_flow",
               "fluid alone: mean and centreline velocity against plane Poiseuille",
               {"fluid.", "domain.", "time.dt_cfd", "time.end", "flow.", "numerics.simple_max_iterations",
                "numerics.simple_tolerance", "numerics.velocity_relaxation", "numerics.pressure_relaxation",
                "numerics.pressure_velocity_coupling", "numerics.piso_correctors",
                "numerics.simple_correctors", "numerics.cfl_max", "output.timeseries_every"},
               {{"fluid.subgrid_model", "\"none\""}},
               false,
               0.0});
  s.push_back(
      {"dem_only",
       "particles alone (optionally a Stokes drag against still fluid): <<w_p>>, contacts, speed",
       {"seed", "particles.", "contact.", "domain.length_x", "domain.width_y", "domain.height_z",
        "domain.periodic_y", "gravity.", "time.dt_dem", "time.dt_cfd", "time.end", "time.average_from",
        "forces.drag", "fluid.viscosity", "numerics.neighbor_skin", "output.timeseries_every"},
       {{"forces.drag", "\"none\""}},
       true,
       a3});
  // The tolerances of the validation studies (tests/regression/driver/validation_studies.sh).
  for (auto& spec : s) {
    if (spec.name == "inclined_settling") {
      spec.tolerances = {{"hindered_settling_rel_error", 0.15, "Richardson-Zaki, periodic suspension"}};
      spec.detects_transient = true;
    }
    if (spec.name == "single_particle")
      spec.tolerances = {{"rel_error", 0.02, "the drag law's isolated terminal velocity"}};
    if (spec.name == "ergun")
      spec.tolerances = {{"max_rel_error_f_star", 0.005, "the Ergun equation (the paper's 0.5 %)"}};
  }
  return s;
}

}  // namespace

const std::vector<SceneSpec>& scene_specs() {
  static const std::vector<SceneSpec> specs = make_specs();
  return specs;
}

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& s : scene_specs()) n.push_back(s.name);
    return n;
  }();
  return names;
}

const SceneSpec& scene_spec(std::string_view name) {
  for (const auto& s : scene_specs())
    if (s.name == name) return s;
  throw InputError(
      fmt::format("scene = \"{}\" is not known: must be one of {}", name, fmt::join(scene_names(), ", ")));
}

bool scene_reads(const SceneSpec& scene, std::string_view key) {
  for (const auto& r : scene.reads) {
    if (r == key) return true;
    if (!r.empty() && r.back() == '.' && key.substr(0, r.size()) == r) return true;
  }
  return false;
}

}  // namespace boycott
