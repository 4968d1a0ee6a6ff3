// A case checked before anything runs: every key against its limits, keys the scene does not
// read refused, the scene's defaults filled in, then the limits between keys (the particles fit
// the box, dt_dem under the spring limit, whole sub-steps, ...). Each error names the key, its
// value and the limit.
#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/case_key_table.hpp"
#include "core/case_params.hpp"
#include "core/error.hpp"
#include "core/scene_specs.hpp"

namespace boycott {

namespace case_keys {
std::string fmt_num(double v) {
  return fmt::format("{:g}", v);
}
}  // namespace case_keys

using namespace case_keys;

namespace {

std::string describe_rule(const Rule& r) {
  if (!r.choices.empty()) return fmt::format("one of {}", fmt::join(r.choices, ", "));
  std::string s;
  if (r.min > -kInf && r.max < kInf)
    s = fmt::format("in {}{}, {}{}", r.min_open ? "(" : "[", fmt_num(r.min), fmt_num(r.max),
                    r.max_open ? ")" : "]");
  else if (r.min > -kInf)
    s = fmt::format("{} {}", r.min_open ? ">" : ">=", fmt_num(r.min));
  else if (r.max < kInf)
    s = fmt::format("{} {}", r.max_open ? "<" : "<=", fmt_num(r.max));
  if (*r.unit) s += fmt::format(" {}", r.unit);
  return s;
}

void check_number(const char* key, double v, const Rule& r) {
  if (std::isnan(v)) {
    if (r.optional) return;
    throw InputError(fmt::format("{} is not a number", key));
  }
  // No key takes an infinite value: a run to time.end = inf would never end.
  if (!std::isfinite(v))
    throw InputError(
        fmt::format("{} = {} is not a finite number: must be {}", key, fmt_num(v), describe_rule(r)));
  const bool ok = (r.min_open ? v > r.min : v >= r.min) && (r.max_open ? v < r.max : v <= r.max);
  if (!ok)
    throw InputError(fmt::format("{} = {} is out of range: must be {}", key, fmt_num(v), describe_rule(r)));
}

void check_value(const char* key, const std::string& v, const Rule& r) {
  if (!r.choices.empty() && std::find(r.choices.begin(), r.choices.end(), v) == r.choices.end())
    throw InputError(fmt::format("{} = \"{}\" is not known: must be {}", key, v, describe_rule(r)));
}
void check_value(const char* key, double v, const Rule& r) {
  check_number(key, v, r);
}
void check_value(const char* key, std::int64_t v, const Rule& r) {
  check_number(key, static_cast<double>(v), r);
}
void check_value(const char*, bool, const Rule&) {}
void check_value(const char* key, const WindowStart& v, const Rule& r) {
  if (!v.automatic) check_number(key, v.time_s, r);
}
template <class T, std::size_t N>
void check_value(const char* key, const std::array<T, N>& a, const Rule& r) {
  for (const auto& x : a) check_number(key, static_cast<double>(x), r);
}
void check_value(const char* key, const std::vector<double>& a, const Rule& r) {
  for (double x : a) check_number(key, x, r);
}

/// The scene's defaults, the particle count and the skin, for the keys the user did not set.
void resolve_defaults(CaseParams& p, const SceneSpec& sc) {
  for (const auto& [key, value] : sc.defaults)
    if (!is_set_key(p, key)) set_key(p, key, value);
  const bool reads_count = scene_reads(sc, "particles.count");
  if (!reads_count) {
    // One sphere by definition (single_particle), or none.
    p.particles.count = sc.fixed_particle_count;
    p.particles.volume_fraction = kUnset;
  } else if (!is_set_key(p, "particles.count") && !is_set(p.particles.volume_fraction)) {
    // Neither given: the scene's solid fraction (Table III's unless the scene has its own) in the
    // case's own box.
    p.particles.volume_fraction = sc.default_solid_fraction;
  }
  if (is_set(p.particles.volume_fraction)) {
    p.particles.count =
        std::llround(p.particles.volume_fraction * p.box_volume_m3() / p.particle_volume_m3());
    p.particles.volume_fraction = kUnset;  // resolved: equal cases hash equal whichever way given
  }
  // The skin must not exceed the diameter (pairs further than d + skin apart never meet within
  // a rebuild); Table III's 0.3 mm where d allows.
  if (!is_set_key(p, "numerics.neighbor_skin"))
    p.numerics.neighbor_skin_m = std::min(NumericsParams{}.neighbor_skin_m, p.particles.diameter_m);
  p.resolved = true;
}

}  // namespace

namespace {

/// Each key against its own limits (a NaN the user wrote is a value, and not a finite one).
void check_each_key(CaseParams& p) {
  visit_keys(p, [&](const char* key, auto& ref, const Rule& r) {
    check_value(key, ref, r);
    // An optional key's NaN means "not set"; set by the user, it is a value, and not a finite one.
    if constexpr (std::is_same_v<std::decay_t<decltype(ref)>, double>)
      if (std::isnan(ref) && is_set_key(p, key) && !p.resolved)
        throw InputError(fmt::format("{} = nan is not a finite number", key));
  });
}

void refuse_keys_the_scene_does_not_read(const CaseParams& p, const SceneSpec& sc) {
  for (const auto& key : p.set_keys)
    if (key != "scene" && !scene_reads(sc, key))
      throw InputError(
          fmt::format("{} is not used by scene {}: the scene would ignore or overwrite it (`boycott "
                      "case keys --scene {}` lists the keys it reads)",
                      key, sc.name, sc.name));
}

/// The particles fit the channel, the periodic lengths and the box.
void check_particles_fit(const CaseParams& p, const SceneSpec& sc) {
  const auto reads = [&](const char* key) { return scene_reads(sc, key); };
  const double d = p.particles.diameter_m;
  const bool particles = reads("particles.diameter");
  if (particles && !p.domain.periodic_y && d >= p.domain.width_y_m)
    throw InputError(
        fmt::format("particles.diameter = {} m does not fit the channel: must be < domain.width_y = {} m",
                    fmt_num(d), fmt_num(p.domain.width_y_m)));
  // The minimum-image convention needs a periodic length of at least two diameters.
  if (particles)
    for (auto [name, len] :
         {std::pair{"domain.length_x", p.domain.length_x_m}, {"domain.height_z", p.domain.height_z_m}})
      if (len < 2.0 * d)
        throw InputError(
            fmt::format("{} = {} m is too short for particles.diameter = {} m: must be >= 2 d = {} m", name,
                        fmt_num(len), fmt_num(d), fmt_num(2.0 * d)));
  // Random close packing of monodisperse spheres: no more can be placed without overlap.
  constexpr double kRandomClosePacking = 0.64;
  const double ap = p.solid_fraction();
  // Soft spheres packed by growth ("packed") sit in slight overlap: the paper's own Ergun bed
  // (Table I, 19561 spheres of 1 mm in 0.02 x 0.02 x 0.04 m) is at 0.6401.
  const double max_fraction =
      p.particles.insertion == "packed" ? kRandomClosePacking + 0.005 : kRandomClosePacking;
  if (reads("particles.count") && ap > max_fraction)
    throw InputError(
        fmt::format("particles.count = {} overfills the box: solid fraction {:.4f} exceeds {} "
                    "(random close packing{})",
                    p.particles.count, ap, max_fraction,
                    p.particles.insertion == "packed" ? " with soft-sphere overlap" : ""));
  if (reads("particles.count") && p.particles.count > 0 && p.particles.insertion == "random" && ap > 0.45)
    throw InputError(
        fmt::format("particles.count = {} (solid fraction {:.4f}) is too dense for random insertion: must be "
                    "<= 0.45; use particles.insertion = \"bed\" or \"packed\"",
                    p.particles.count, ap));
  // A scene that places particles measures them: none is nothing to measure (a settling
  // velocity of 0 would be stored as a result).
  if (sc.has_particles && reads("particles.count") && p.particles.count < 1)
    throw InputError(fmt::format("particles.count = {}: scene {} needs at least one particle",
                                 p.particles.count, sc.name));
}

/// The DEM step under the spring limit, whole sub-steps per fluid step, and a run that ends.
void check_time_steps(const CaseParams& p, const SceneSpec& sc) {
  const auto reads = [&](const char* key) { return scene_reads(sc, key); };
  const double limit = p.dem_spring_limit_s();
  if (reads("particles.diameter") && p.particles.count > 0 && reads("time.dt_dem") && p.time.dt_dem_s > limit)
    throw InputError(fmt::format(
        "time.dt_dem = {:.4g} us exceeds the spring limit (pi/5) sqrt(m/k_n) = {:.4g} us for "
        "contact.stiffness = {} N/m "
        "and particle mass {:.4g} kg",
        p.time.dt_dem_s * 1e6, limit * 1e6, fmt_num(p.contact.stiffness_n_m), p.particle_mass_kg()));
  if (reads("time.dt_dem") && reads("time.dt_cfd")) {
    if (p.time.dt_dem_s > p.time.dt_cfd_s * (1.0 + 1e-12))
      throw InputError(fmt::format("time.dt_dem = {} s must be <= time.dt_cfd = {} s",
                                   fmt_num(p.time.dt_dem_s), fmt_num(p.time.dt_cfd_s)));
    const double ratio = p.time.dt_cfd_s / p.time.dt_dem_s;
    if (std::abs(ratio - std::round(ratio)) > 1e-6 * ratio)
      throw InputError(
          fmt::format("time.dt_cfd / time.dt_dem = {} must be a whole number of DEM sub-steps", ratio));
    // The paper's cases take 50 sub-steps per fluid step. A long step is stoppable inside its
    // sub-steps (CoupledSystem::set_interrupt), but a stop drops the whole step: beyond this
    // many, one step is more work than a run should risk losing, and no case needs it.
    constexpr double kMaxSubsteps = 1e5;
    if (ratio > kMaxSubsteps * (1.0 + 1e-9))
      throw InputError(
          fmt::format("time.dt_cfd / time.dt_dem = {:.6g} DEM sub-steps per fluid step: must be at "
                      "most {:g} (a stop drops the unfinished fluid step; the paper's cases take 50)",
                      ratio, kMaxSubsteps));
  }
  // A step so small that the run would not end in any time a machine has.
  constexpr double kMaxSteps = 1e12;
  for (auto [key, dt] : {std::pair{"time.dt_dem", p.time.dt_dem_s}, {"time.dt_cfd", p.time.dt_cfd_s}})
    if (reads(key) && reads("time.end") && p.time.end_s / dt > kMaxSteps)
      throw InputError(
          fmt::format("{} = {} s would take {:.3g} steps to time.end = {} s: must be at most {:g}", key,
                      fmt_num(dt), p.time.end_s / dt, fmt_num(p.time.end_s), kMaxSteps));
}

/// Model and numerics keys that contradict each other or that the solver cannot represent.
void check_models_and_grid(const CaseParams& p, const SceneSpec& sc) {
  const auto reads = [&](const char* key) { return scene_reads(sc, key); };
  // The SIMPLE iteration is SIMPLEC (fluid/pressure_correction.cpp), whose pressure correction
  // is consistent with its velocity correction and is applied whole: a relaxation factor would be
  // silently ignored, yet change the case id. The key stays for case files that spell out its
  // default.
  if (reads("numerics.pressure_relaxation") &&
      p.numerics.pressure_relaxation != NumericsParams{}.pressure_relaxation)
    throw InputError(fmt::format(
        "numerics.pressure_relaxation = {}: must be {} (its default). The pressure-velocity coupling is "
        "SIMPLEC, which applies its pressure correction whole; to damp the iteration use "
        "numerics.velocity_relaxation",
        fmt_num(p.numerics.pressure_relaxation), fmt_num(NumericsParams{}.pressure_relaxation)));
  // A law other than the default named beside saffman_lift = false (a case written back with every
  // key holds the default law there, which the switch turns off).
  if (reads("forces.lift") && !p.forces.saffman_lift && p.forces.lift != ForceParams{}.lift &&
      p.forces.lift != "none")
    throw InputError(
        fmt::format("forces.lift = \"{}\" contradicts forces.saffman_lift = false (which means no "
                    "lift): leave one of them out",
                    p.forces.lift));
  // The fluid grid needs two cells per direction (its stencils and wall rules): refused here, before
  // a run folder is written, not when the solver is built.
  if (reads("domain.cells") && sc.has_fluid)
    for (int d = 0; d < 3; ++d)
      if (p.domain.cells[d] < 2)
        throw InputError(fmt::format(
            "domain.cells = [{}, {}, {}]: the fluid grid needs at least 2 cells per "
            "direction ({} has {})",
            p.domain.cells[0], p.domain.cells[1], p.domain.cells[2], "xyz"[d], p.domain.cells[d]));
  if (reads("numerics.neighbor_skin") && p.numerics.neighbor_skin_m > p.particles.diameter_m)
    throw InputError(fmt::format("numerics.neighbor_skin = {} m must be <= particles.diameter = {} m",
                                 fmt_num(p.numerics.neighbor_skin_m), fmt_num(p.particles.diameter_m)));
}

/// Output times (each writes a file) and the averaging window.
void check_outputs_and_window(const CaseParams& p, const SceneSpec& sc) {
  const auto reads = [&](const char* key) { return scene_reads(sc, key); };
  // Each time writes a file: a bounded number of them, none twice.
  for (auto [key, times] : {std::pair{"output.snapshot_times", &p.output.snapshot_times_s},
                            std::pair{"output.image_times", &p.output.image_times_s}}) {
    if (!reads(key)) continue;
    constexpr std::size_t kMaxTimes = 10000;
    if (times->size() > kMaxTimes)
      throw InputError(fmt::format("{} lists {} times: must be at most {} (each writes a file)", key,
                                   times->size(), kMaxTimes));
    std::vector<double> sorted = *times;
    std::sort(sorted.begin(), sorted.end());
    if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end())
      throw InputError(
          fmt::format("{} lists {} s more than once: each time may appear once", key, fmt_num(*dup)));
  }
  if (reads("time.average_from") && p.time.average_from.automatic && !sc.detects_transient)
    throw InputError(
        fmt::format("time.average_from = \"auto\" is not taken by scene {}: it keeps no per-step "
                    "series to find its transient in; give a time in s",
                    sc.name),
        "time.average_from");
  if (reads("time.average_from") && !p.time.average_from.automatic &&
      p.time.average_from.time_s >= p.time.end_s)
    throw InputError(fmt::format(
        "time.average_from = {} s{} must be < time.end = {} s", fmt_num(p.time.average_from.time_s),
        is_set_key(p, "time.average_from") ? "" : " (Table III's default)", fmt_num(p.time.end_s)));
}

/// The key rules, in order: each key alone, the scene's keys and defaults, the limits between keys.
void check_key_rules(CaseParams& p) {
  check_each_key(p);
  const SceneSpec& sc = scene_spec(p.scene);
  refuse_keys_the_scene_does_not_read(p, sc);
  if (!p.resolved) resolve_defaults(p, sc);
  check_particles_fit(p, sc);
  check_time_steps(p, sc);
  check_models_and_grid(p, sc);
  check_outputs_and_window(p, sc);
}

}  // namespace

void validate(CaseParams& p) {
  try {
    check_key_rules(p);
  } catch (const InputError& e) {
    if (!e.key().empty()) throw;
    // Every message of check_key_rules begins with the key at fault ("time.dt_dem = ..."): named as the
    // error's key, a caller holding the file can say which line set it.
    std::string key;
    const std::string what = e.what();
    for (const auto& k : case_key_names())
      if (what.rfind(k, 0) == 0 && what.size() > k.size() &&
          (what[k.size()] == ' ' || what[k.size()] == ':') && k.size() > key.size())
        key = k;
    throw InputError(what, key);
  }
}

}  // namespace boycott
