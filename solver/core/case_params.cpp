// Quantities derived from a case, its identity (case_id: the hash of its canonical JSON, output
// keys left out) and the lists of key names. Reading is in case_parse.cpp, checking in
// case_rules.cpp; the key table they share is case_key_table.hpp.
#include <algorithm>
#include <array>
#include <cmath>

#include "core/case_key_table.hpp"
#include "core/case_params.hpp"
#include "core/constants.hpp"
#include "core/hash.hpp"
#include "core/scene_specs.hpp"

namespace boycott {

using namespace case_keys;

double CaseParams::particle_volume_m3() const {
  return kPi / 6.0 * particles.diameter_m * particles.diameter_m * particles.diameter_m;
}
double CaseParams::particle_mass_kg() const {
  return particles.density_kg_m3 * particle_volume_m3();
}
double CaseParams::box_volume_m3() const {
  return domain.length_x_m * domain.width_y_m * domain.height_z_m;
}
double CaseParams::solid_fraction() const {
  return static_cast<double>(particles.count) * particle_volume_m3() / box_volume_m3();
}
std::array<double, 3> CaseParams::gravity_vector() const {
  const double th = gravity.angle_deg * kPi / 180.0;
  // Exact zeros at 0 and 90 degrees, so that theta = 90 has no spurious y component.
  const double c = gravity.angle_deg == 90.0 ? 0.0 : std::cos(th);
  const double s = gravity.angle_deg == 0.0 ? 0.0 : std::sin(th);
  return {0.0, -gravity.magnitude_m_s2 * c, -gravity.magnitude_m_s2 * s};
}
double CaseParams::dem_spring_limit_s() const {
  return kPi / 5.0 * std::sqrt(particle_mass_kg() / contact.stiffness_n_m);
}
std::int64_t CaseParams::dem_substeps() const {
  return std::max<std::int64_t>(1, std::llround(time.dt_cfd_s / time.dt_dem_s));
}

bool is_output_only_key(const std::string& key) {
  return key == "time.end" || key == "time.checkpoint_every" || key == "time.target_rel_error" ||
         key.rfind("output.", 0) == 0;
}

std::string case_id(const CaseParams& p) {
  nlohmann::json j = to_json(p);
  for (const auto& key : case_key_names(p.scene))
    if (is_output_only_key(key)) {
      const auto ptr = pointer_of(key);
      if (j.contains(ptr)) j.at(ptr.parent_pointer()).erase(ptr.back());
    }
  // One lift, one id: forces.lift = "none" is saffman_lift = false, which leaves forces.lift out.
  if (const auto lift = pointer_of("forces.lift"); j.contains(lift)) {
    const auto on = pointer_of("forces.saffman_lift");
    if (j.at(lift) == "none" && j.contains(on)) j.at(on) = false;
    if (j.contains(on) && j.at(on) == false) {
      j.at(lift.parent_pointer()).erase(lift.back());
      // Without lift the vorticity is not used.
      if (const auto vort = pointer_of("numerics.vorticity"); j.contains(vort))
        j.at(vort.parent_pointer()).erase(vort.back());
    }
  }
  for (const auto& late : kLateKeys) {
    const auto ptr = pointer_of(late.key);
    if (j.contains(ptr) && j.at(ptr) == nlohmann::json::parse(late.old_behaviour))
      j.at(ptr.parent_pointer()).erase(ptr.back());
  }
  // Sections left empty (all their keys output-only) are dropped, as if never there.
  for (auto it = j.begin(); it != j.end();) it = it->is_object() && it->empty() ? j.erase(it) : std::next(it);
  j["identity_version"] = kCaseIdVersion;
  // nlohmann's object keys are sorted (std::map), so dump() is canonical.
  return hex64(fnv1a64(j.dump()));
}

std::string case_id_of_json(const std::string& canonical_json) {
  return case_id(case_from_json(nlohmann::json::parse(canonical_json)));
}

std::vector<std::string> case_key_names() {
  std::vector<std::string> names;
  CaseParams p;
  visit_keys(p, [&](const char* key, auto&, const Rule&) { names.emplace_back(key); });
  return names;
}

std::vector<std::string> case_key_names(const std::string& scene) {
  const SceneSpec& sc = scene_spec(scene);
  std::vector<std::string> names;
  for (const auto& key : case_key_names())
    if (key == "scene" || scene_reads(sc, key)) names.push_back(key);
  return names;
}

}  // namespace boycott
