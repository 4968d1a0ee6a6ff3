#pragma once
// A scene is a function from a validated case to a finished run folder (summary.json,
// timeseries.csv, ...). Scenes switch on only the physics they need and record it in
// ModelTimers, which every summary lists.
#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"

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

/// The scene table: name -> function. Throws InputError for a name not in core's scene list.
SceneFn find_scene(const std::string& name);
/// The names the scene table holds (a test checks them against core/scene_specs.hpp's list).
std::vector<std::string> registered_scenes();

/// Validates, writes params.json beside the outputs (refusing a folder that holds another case)
/// and runs the scene. A folder whose run already reached time.end says so and returns 0; a
/// time.end below the time it reached is refused; with ctx.branch_from, the parent checkpoint
/// is chosen and checked against the case (what cannot change mid-run is refused).
int run_case(CaseParams params, RunContext& ctx);

}  // namespace boycott::scenes
