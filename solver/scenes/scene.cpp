#include "scenes/scene.hpp"

#include <map>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::scenes {

namespace {
/// Filled before main by the scenes' registrations (a function's static, so that it exists
/// whichever scene file registers first).
std::map<std::string, SceneFn>& run_table() {
  static std::map<std::string, SceneFn> table;
  return table;
}
}  // namespace

SceneRegistration::SceneRegistration(SceneSpec spec, SceneFn run) {
  const std::string name = spec.name;
  register_scene_spec(std::move(spec));
  run_table().emplace(name, run);
}

SceneFn find_scene(const std::string& name) {
  scene_spec(name);  // names the known scenes when it is not one
  const auto it = run_table().find(name);
  if (it == run_table().end())
    throw InputError(fmt::format("scene '{}' has no run function in the scene table", name));
  return it->second;
}

std::vector<std::string> registered_scenes() {
  std::vector<std::string> names;
  for (const auto& [name, fn] : run_table()) names.push_back(name);
  return names;
}

}  // namespace boycott::scenes
