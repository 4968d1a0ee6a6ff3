#include "core/scene_specs.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/constants.hpp"
#include "core/error.hpp"

namespace boycott {

double table3_solid_fraction() {
  const double d = 0.6e-3, vp = kPi / 6.0 * d * d * d;
  return 120000.0 * vp / (0.2 * 0.006 * 0.1);
}

std::vector<std::string> coupled_scene_keys() {
  return {"seed", "fluid.", "particles.", "contact.", "domain.", "gravity.", "time.", "forces.", "numerics."};
}

namespace {
/// Filled before main by the scenes' registrations; a function's static, so that it exists
/// whichever translation unit registers first.
std::vector<SceneSpec>& table() {
  static std::vector<SceneSpec> specs;
  return specs;
}
}  // namespace

void register_scene_spec(SceneSpec spec) {
  auto& specs = table();
  const auto at = std::lower_bound(specs.begin(), specs.end(), spec.name,
                                   [](const SceneSpec& s, const std::string& n) { return s.name < n; });
  if (at != specs.end() && at->name == spec.name)
    throw std::logic_error(fmt::format("scene '{}' is declared twice", spec.name));
  // In name order: the listing does not depend on the order in which the linker lays out files.
  specs.insert(at, std::move(spec));
}

const std::vector<SceneSpec>& scene_specs() {
  return table();
}

std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  for (const auto& s : scene_specs()) names.push_back(s.name);
  return names;
}

const SceneSpec& scene_spec(std::string_view name) {
  for (const auto& s : scene_specs())
    if (s.name == name) return s;
  if (scene_specs().empty())
    throw InputError(fmt::format("scene = \"{}\": this program links no scenes", name));
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
