#pragma once
// A scene is a function from a validated case to a finished run folder (summary.json,
// timeseries.csv, ...). Scenes switch on only the physics they need and record it in
// ModelTimers, which every summary lists.
//
// Each scene is one file of this folder that declares itself at namespace scope:
//
//   const SceneRegistration kRegistered{{.name = "my_scene", .measures = "...", .reads = {...},
//                                        .own_checks = &my_checks},
//                                       &run_my_scene};
//
// and one line in this folder's CMakeLists.txt. The declaration enters core's scene table (its
// keys, defaults and checks: core/scene_specs.hpp) and this folder's run table before main.
#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/scene_specs.hpp"

namespace boycott::scenes {

struct RunContext {
  std::filesystem::path out_dir;
  /// Set asynchronously by SIGINT/SIGTERM: the scene finishes its step, checkpoints, returns 75.
  const std::atomic<bool>* stop_requested = nullptr;
  bool quiet = false;
  /// Progress callback (simulated time s), for the driver's display; may be empty.
  std::function<void(double)> progress;
  /// A short note for the progress line before each progress call (a scene's main quantity so
  /// far, e.g. "mean_wp_m_s -0.0816"); may be empty.
  std::function<void(const std::string&)> progress_note;
  /// Branch (`case run --from DIR --at TIME`): start from DIR's newest kept checkpoint at or
  /// before TIME (s; unset: the newest), with this case's parameters and fresh statistics.
  std::filesystem::path branch_from;
  double branch_at_s = kUnset;
  /// The parent checkpoint run_case chose (set by run_case; scenes read it).
  std::filesystem::path branch_checkpoint;
  /// Whether to stop at the end of this step. Collective under MPI (every rank calls it once per
  /// step): a signal that reached one rank stops all of them at the same step.
  bool should_stop() const;
};

/// Runs (or resumes) a case. Returns the process exit code (error.hpp); writes summary.json.
using SceneFn = int (*)(const CaseParams&, RunContext&);

/// A scene's declaration: its spec (into core's scene table) and its run function (into the run
/// table). Defined once per scene file, at namespace scope.
struct SceneRegistration {
  SceneRegistration(SceneSpec spec, SceneFn run);
};

/// The run table: name -> function. Throws InputError for a name not in core's scene table.
SceneFn find_scene(const std::string& name);
/// The names the run table holds (a test checks them against core's scene table).
std::vector<std::string> registered_scenes();

}  // namespace boycott::scenes
