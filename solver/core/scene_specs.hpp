#pragma once
// The table of scenes: for each, its name, what it measures, the case keys it reads and its own
// defaults. Parsing refuses a key the scene would not read (or would overwrite), the case id
// hashes only the keys it reads, `case keys --scene` lists them, and scenes/registry.cpp maps
// each name to its code (a test checks that the two agree).
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace boycott {

struct SceneSpec {
  std::string name;
  std::string measures;  ///< one line, for `case keys` and the README
  /// The keys the scene reads: a whole section ("fluid.") or one key ("time.dt_dem", "seed").
  std::vector<std::string> reads;
  /// The scene's own defaults where they differ from Table III's, as TOML values.
  std::vector<std::pair<std::string, std::string>> defaults;
  /// Places particles: particles.count follows the case's box when the case does not set it.
  bool has_particles = true;
  /// Solid fraction of the default particle load (Table III's, or the scene's own).
  double default_solid_fraction = 0.0;
  /// The validation errors the scene reports (summary.json keys) with the tolerance each is
  /// held to, for `query validation`'s pass/fail (the validation tests hold the same ones).
  struct Tolerance {
    std::string error_key;
    double max_abs = 0.0;
    std::string against;  ///< what the error is measured against
  };
  std::vector<Tolerance> tolerances = {};
  /// Keeps <w_p>'s whole per-step series and finds where its start-up transient ends: it takes
  /// time.average_from = "auto".
  bool detects_transient = false;
};

/// Table III's solid fraction: 120 000 particles of 0.6 mm in the 0.2 x 0.006 x 0.1 m box.
double table3_solid_fraction();

/// Every scene, in the order the documentation lists them.
const std::vector<SceneSpec>& scene_specs();
/// The names of scene_specs(), in order.
const std::vector<std::string>& scene_names();
/// The scene named `name`; throws InputError naming the known scenes otherwise.
const SceneSpec& scene_spec(std::string_view name);
/// Whether `scene` reads the dotted key `key`.
bool scene_reads(const SceneSpec& scene, std::string_view key);

}  // namespace boycott
