#pragma once
// The table of scenes: for each, its name, what it measures, the case keys it reads, its own
// defaults and its own checks. Each scene declares itself in its one file under solver/scenes/
// (scenes/scene.hpp: SceneRegistration, which also records its run function), as a LAMMPS style
// registers: nothing else names a scene. Parsing refuses a key the scene would not read (or would
// overwrite), the case id hashes only the keys it reads, `case keys --scene` lists them, and the
// pre-flight (checks/) adds the scene's own findings.
//
// A program knows the scenes it links: the `boycott` program and every test that reads cases link
// the scenes library whole (solver/scenes/CMakeLists.txt), so no declaration is dropped.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace boycott {

struct CaseParams;

/// What a scene's own check of a resolved case found (merged into the pre-flight report).
struct SceneFindings {
  std::vector<std::string> errors;    ///< cannot work: the case is refused
  std::vector<std::string> warnings;  ///< doubtful: the run goes ahead
};

// Every member has an initializer, so that a declaration names only what differs (designated
// initializers in the scene files).
struct SceneSpec {
  std::string name = {};
  std::string measures = {};  ///< one line, for `case keys` and the README
  /// The keys the scene reads: a whole section ("fluid.") or one key ("time.dt_dem", "seed").
  std::vector<std::string> reads = {};
  /// The scene's own defaults where they differ from Table III's, as TOML values.
  std::vector<std::pair<std::string, std::string>> defaults = {};
  /// Places particles: particles.count follows the case's box when the case does not set it.
  bool has_particles = true;
  /// Particles of a scene that does not read particles.count (one sphere, or none).
  std::int64_t fixed_particle_count = 0;
  /// Solid fraction of the default particle load (Table III's, or the scene's own).
  double default_solid_fraction = 0.0;
  /// Solves the fluid (it then needs a grid of at least 2 cells per direction).
  bool has_fluid = true;
  /// Its particles move (a frozen bed has neither settling nor contacts to check).
  bool particles_move = true;
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
  /// The scene's own limits between keys, beyond the key rules and the general pre-flight.
  void (*own_checks)(const CaseParams&, SceneFindings&) = nullptr;
};

/// Table III's solid fraction: 120 000 particles of 0.6 mm in the 0.2 x 0.006 x 0.1 m box.
double table3_solid_fraction();
/// The keys of a coupled CFD-DEM run: the fluid (its forcing is the scene's own), the particles,
/// their contacts and the fluid forces on them, the time steps and the numerics.
std::vector<std::string> coupled_scene_keys();

/// Adds a scene to the table (scenes/scene.hpp's SceneRegistration calls it before main).
/// A second scene of the same name is a programming error: std::logic_error.
void register_scene_spec(SceneSpec spec);

/// Every scene this program links, by name.
const std::vector<SceneSpec>& scene_specs();
/// The names of scene_specs(), in order.
std::vector<std::string> scene_names();
/// The scene named `name`; throws InputError naming the known scenes otherwise.
const SceneSpec& scene_spec(std::string_view name);
/// Whether `scene` reads the dotted key `key`.
bool scene_reads(const SceneSpec& scene, std::string_view key);

}  // namespace boycott
