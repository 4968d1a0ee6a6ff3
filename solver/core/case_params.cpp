#include "core/case_params.hpp"

#include <algorithm>
#include <array>
#include <fstream>
#include <set>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"
#include "core/key_docs.hpp"
#include "core/model_names.hpp"

namespace boycott {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

Rule positive(const char* unit) {
  return Rule{0.0, kInf, true, false, {}, unit};
}
Rule nonneg(const char* unit) {
  return Rule{0.0, kInf, false, false, {}, unit};
}
Rule range(double a, double b, const char* unit = "") {
  return Rule{a, b, false, false, {}, unit};
}
Rule open_range(double a, double b, bool lo_open, bool hi_open, const char* unit = "") {
  return Rule{a, b, lo_open, hi_open, {}, unit};
}
Rule any(const char* unit = "") {
  return Rule{-kInf, kInf, false, false, {}, unit};
}
Rule optional(Rule r) {
  r.optional = true;
  return r;
}
Rule choice(std::vector<std::string> c) {
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
  v("time.average_from", p.time.average_from_s, nonneg("s"));
  v("time.checkpoint_every", p.time.checkpoint_every_s, positive("s"));
  v("time.target_rel_error", p.time.target_rel_error, optional(open_range(0.0, 1.0, true, true)));

  v("forces.drag", p.forces.drag, choice(drag_law_names()));
  v("forces.saffman_lift", p.forces.saffman_lift, any());
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
  v("numerics.cfl_max", p.numerics.cfl_max, open_range(0.0, 1.0, true, false));
  v("numerics.neighbor_skin", p.numerics.neighbor_skin_m, positive("m"));
  v("numerics.void_fraction_kernel", p.numerics.void_fraction_kernel, choice(kernel_names()));
  v("numerics.sampling", p.numerics.sampling, choice(sampling_names()));

  v("output.timeseries_every", p.output.timeseries_every_s, optional(positive("s")));
  v("output.keep_checkpoints", p.output.keep_checkpoints, range(1, 1000));
  v("output.snapshot_times", p.output.snapshot_times_s, nonneg("s"));
  v("output.image_times", p.output.image_times_s, nonneg("s"));
  v("output.pdf_bins", p.output.pdf_bins, range(2, 100000));

  v("ergun.pressure_gradients", p.ergun.pressure_gradients_pa_m, positive("Pa/m"));
  v("sediment.bulk_velocity", p.sediment.bulk_velocity_m_s, any("m/s"));
  v("sediment.bed_height", p.sediment.bed_height_m, optional(positive("m")));
  v("sediment.initial_flow", p.sediment.initial_flow, choice({"turbulent", "rest"}));
}

std::string fmt_num(double v) {
  return fmt::format("{:g}", v);
}

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
template <class T, std::size_t N>
void check_value(const char* key, const std::array<T, N>& a, const Rule& r) {
  for (const auto& x : a) check_number(key, static_cast<double>(x), r);
}
void check_value(const char* key, const std::vector<double>& a, const Rule& r) {
  for (double x : a) check_number(key, x, r);
}

// ---- conversions from a generic node (TOML or JSON, through a small adaptor) ----

[[noreturn]] void type_error(const char* key, const char* want, const std::string& got) {
  throw InputError(fmt::format("{} must be {}, got {}", key, want, got));
}

std::string toml_repr(const toml::node& n) {
  std::ostringstream os;
  if (auto* t = n.as_table())
    os << *t;
  else if (auto* a = n.as_array())
    os << *a;
  else
    n.visit([&](auto&& v) { os << v; });
  return os.str();
}

double toml_number(const char* key, const toml::node& n) {
  if (auto v = n.value_exact<double>()) return *v;
  if (auto v = n.value_exact<std::int64_t>()) return static_cast<double>(*v);
  type_error(key, "a number", toml_repr(n));
}

void from_toml(const char* key, const toml::node& n, double& out) {
  out = toml_number(key, n);
}
void from_toml(const char* key, const toml::node& n, std::int64_t& out) {
  if (auto v = n.value_exact<std::int64_t>()) {
    out = *v;
    return;
  }
  if (auto v = n.value_exact<double>(); v && std::floor(*v) == *v && std::abs(*v) < 9.0e18) {
    out = static_cast<std::int64_t>(*v);
    return;
  }
  type_error(key, "an integer", toml_repr(n));
}
void from_toml(const char* key, const toml::node& n, bool& out) {
  if (auto v = n.value_exact<bool>()) {
    out = *v;
    return;
  }
  type_error(key, "true or false", toml_repr(n));
}
void from_toml(const char* key, const toml::node& n, std::string& out) {
  if (auto v = n.value_exact<std::string>()) {
    out = *v;
    return;
  }
  type_error(key, "a string", toml_repr(n));
}
template <class T, std::size_t N>
void from_toml(const char* key, const toml::node& n, std::array<T, N>& out) {
  const auto* a = n.as_array();
  if (!a || a->size() != N) type_error(key, fmt::format("an array of {} numbers", N).c_str(), toml_repr(n));
  for (std::size_t i = 0; i < N; ++i) from_toml(key, *a->get(i), out[i]);
}
void from_toml(const char* key, const toml::node& n, std::vector<double>& out) {
  const auto* a = n.as_array();
  if (!a) type_error(key, "an array of numbers", toml_repr(n));
  out.clear();
  for (const auto& e : *a) out.push_back(toml_number(key, e));
}

void from_json(const char* key, const nlohmann::json& j, double& out) {
  if (j.is_null())
    out = kUnset;
  else if (j.is_number())
    out = j.get<double>();
  else
    type_error(key, "a number", j.dump());
}
void from_json(const char* key, const nlohmann::json& j, std::int64_t& out) {
  if (!j.is_number_integer()) type_error(key, "an integer", j.dump());
  out = j.get<std::int64_t>();
}
void from_json(const char* key, const nlohmann::json& j, bool& out) {
  if (!j.is_boolean()) type_error(key, "true or false", j.dump());
  out = j.get<bool>();
}
void from_json(const char* key, const nlohmann::json& j, std::string& out) {
  if (!j.is_string()) type_error(key, "a string", j.dump());
  out = j.get<std::string>();
}
template <class T, std::size_t N>
void from_json(const char* key, const nlohmann::json& j, std::array<T, N>& out) {
  if (!j.is_array() || j.size() != N) type_error(key, "an array of 3 numbers", j.dump());
  for (std::size_t i = 0; i < N; ++i) from_json(key, j[i], out[i]);
}
void from_json(const char* key, const nlohmann::json& j, std::vector<double>& out) {
  if (!j.is_array()) type_error(key, "an array of numbers", j.dump());
  out.clear();
  for (const auto& e : j) {
    double v;
    from_json(key, e, v);
    out.push_back(v);
  }
}

nlohmann::json json_value(double v) {
  return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v);
}
template <class T>
nlohmann::json json_value(const T& v) {
  return nlohmann::json(v);
}

/// Splits "a.b" into the JSON pointer "/a/b".
nlohmann::json::json_pointer pointer_of(const std::string& dotted) {
  std::string s = "/" + dotted;
  std::replace(s.begin(), s.end(), '.', '/');
  return nlohmann::json::json_pointer(s);
}

void collect_toml_keys(const toml::table& t, const std::string& prefix, std::vector<std::string>& out) {
  for (const auto& [k, node] : t) {
    std::string name = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = node.as_table())
      collect_toml_keys(*sub, name, out);
    else
      out.push_back(name);
  }
}

CaseParams from_toml_table(const toml::table& tbl) {
  CaseParams p;
  std::set<std::string> known;
  visit_keys(p, [&](const char* key, auto& ref, const Rule&) {
    known.insert(key);
    if (auto node = tbl.at_path(key)) {
      from_toml(key, *node.node(), ref);
      p.set_keys.emplace_back(key);
    }
  });
  std::sort(p.set_keys.begin(), p.set_keys.end());
  std::vector<std::string> present;
  collect_toml_keys(tbl, "", present);
  for (const auto& k : present) {
    if (!known.count(k))
      throw InputError(fmt::format("unknown key '{}'{} (see `boycott case keys`)", k, did_you_mean(k)));
  }
  return p;
}

}  // namespace

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

CaseParams parse_case_string(const std::string& text, const std::string& origin) {
  toml::table tbl;
  try {
    tbl = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", origin, src.begin.line, src.begin.column,
                                 e.description()));
  }
  return from_toml_table(tbl);
}

CaseParams parse_case_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("cannot read case file '{}'", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_case_string(ss.str(), path);
}

CaseParams case_from_json(const nlohmann::json& j) {
  CaseParams p;
  visit_keys(p, [&](const char* key, auto& ref, const Rule&) {
    auto ptr = pointer_of(key);
    if (j.contains(ptr)) from_json(key, j.at(ptr), ref);
  });
  if (j.contains("branch")) {
    from_json("branch.parent_id", j["branch"].value("parent_id", nlohmann::json("")), p.branch.parent_id);
    from_json("branch.parent_time_s", j["branch"].value("parent_time_s", nlohmann::json(nullptr)),
              p.branch.parent_time_s);
  }
  // The canonical form holds resolved values (written after validate()).
  p.resolved = true;
  return p;
}

namespace {
/// Sets one key from a TOML value; returns false for an unknown key.
bool set_key(CaseParams& p, const std::string& key, const std::string& value) {
  toml::table t;
  try {
    t = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    // A bare word is a string: --set scene=ergun.
    t = toml::parse("v = \"" + value + "\"");
  }
  bool found = false;
  visit_keys(p, [&](const char* k, auto& ref, const Rule&) {
    if (key == k) {
      from_toml(k, *t.get("v"), ref);
      found = true;
    }
  });
  return found;
}

bool is_set_key(const CaseParams& p, const std::string& key) {
  return std::binary_search(p.set_keys.begin(), p.set_keys.end(), key);
}
}  // namespace

void apply_override(CaseParams& p, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set '{}': expected key=value", assignment));
  std::string key = assignment.substr(0, eq);
  std::string value = assignment.substr(eq + 1);
  key.erase(key.find_last_not_of(" \t") + 1);
  if (!set_key(p, key, value))
    throw InputError(
        fmt::format("--set: unknown key '{}'{} (see `boycott case keys`)", key, did_you_mean(key)));
  p.set_keys.insert(std::lower_bound(p.set_keys.begin(), p.set_keys.end(), key), key);
  p.set_keys.erase(std::unique(p.set_keys.begin(), p.set_keys.end()), p.set_keys.end());
  // The particle load is given one way or the other; the later assignment wins (otherwise a
  // count set over a case file's volume_fraction would be silently ignored).
  if (key == "particles.count") {
    p.particles.volume_fraction = kUnset;
    p.set_keys.erase(std::remove(p.set_keys.begin(), p.set_keys.end(), "particles.volume_fraction"),
                     p.set_keys.end());
  }
  if (key == "particles.volume_fraction")
    p.set_keys.erase(std::remove(p.set_keys.begin(), p.set_keys.end(), "particles.count"), p.set_keys.end());
}

namespace {

/// The scene's defaults, the particle count and the skin, for the keys the user did not set.
void resolve_defaults(CaseParams& p, const SceneSpec& sc) {
  for (const auto& [key, value] : sc.defaults)
    if (!is_set_key(p, key)) set_key(p, key, value);
  const bool reads_count = scene_reads(sc, "particles.count");
  if (!reads_count) {
    // single_particle is one sphere by definition; scenes without particles have none.
    p.particles.count = sc.name == "single_particle" ? 1 : 0;
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

void validate(CaseParams& p) {
  visit_keys(p, [&](const char* key, auto& ref, const Rule& r) {
    check_value(key, ref, r);
    // An optional key's NaN means "not set"; set by the user, it is a value, and not a finite one.
    if constexpr (std::is_same_v<std::decay_t<decltype(ref)>, double>)
      if (std::isnan(ref) && is_set_key(p, key) && !p.resolved)
        throw InputError(fmt::format("{} = nan is not a finite number", key));
  });
  const SceneSpec& sc = scene_spec(p.scene);
  for (const auto& key : p.set_keys)
    if (key != "scene" && !scene_reads(sc, key))
      throw InputError(
          fmt::format("{} is not used by scene {}: the scene would ignore or overwrite it (`boycott "
                      "case keys --scene {}` lists the keys it reads)",
                      key, sc.name, sc.name));
  if (!p.resolved) resolve_defaults(p, sc);
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
  const double limit = p.dem_spring_limit_s();
  if (particles && p.particles.count > 0 && reads("time.dt_dem") && p.time.dt_dem_s > limit)
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
  }
  // A step so small that the run would not end in any time a machine has.
  constexpr double kMaxSteps = 1e12;
  for (auto [key, dt] : {std::pair{"time.dt_dem", p.time.dt_dem_s}, {"time.dt_cfd", p.time.dt_cfd_s}})
    if (reads(key) && reads("time.end") && p.time.end_s / dt > kMaxSteps)
      throw InputError(
          fmt::format("{} = {} s would take {:.3g} steps to time.end = {} s: must be at most {:g}", key,
                      fmt_num(dt), p.time.end_s / dt, fmt_num(p.time.end_s), kMaxSteps));
  if (reads("time.average_from") && p.time.average_from_s >= p.time.end_s)
    throw InputError(fmt::format(
        "time.average_from = {} s{} must be < time.end = {} s", fmt_num(p.time.average_from_s),
        is_set_key(p, "time.average_from") ? "" : " (Table III's default)", fmt_num(p.time.end_s)));
  if (reads("numerics.neighbor_skin") && p.numerics.neighbor_skin_m > d)
    throw InputError(fmt::format("numerics.neighbor_skin = {} m must be <= particles.diameter = {} m",
                                 fmt_num(p.numerics.neighbor_skin_m), fmt_num(d)));
}

nlohmann::json to_json(const CaseParams& p) {
  const SceneSpec* sc = nullptr;
  for (const auto& s : scene_specs())
    if (s.name == p.scene) sc = &s;
  nlohmann::json j = nlohmann::json::object();
  visit_keys(p, [&](const char* key, const auto& ref, const Rule&) {
    if (std::string_view(key) == "scene" || !sc || scene_reads(*sc, key))
      j[pointer_of(key)] = json_value(ref);
  });
  if (!p.branch.parent_id.empty())
    j["branch"] = {{"parent_id", p.branch.parent_id}, {"parent_time_s", json_value(p.branch.parent_time_s)}};
  return j;
}

nlohmann::json to_json_all_keys(const CaseParams& p) {
  nlohmann::json j = nlohmann::json::object();
  visit_keys(p, [&](const char* key, const auto& ref, const Rule&) { j[pointer_of(key)] = json_value(ref); });
  return j;
}

bool is_output_only_key(const std::string& key) {
  return key == "time.end" || key == "time.checkpoint_every" || key == "time.target_rel_error" ||
         key.rfind("output.", 0) == 0;
}

namespace {
/// Keys added after identity version 2, each with the value that reproduces the behaviour
/// before it existed: the key enters a case's id only when its value differs from that, so
/// adding a key never changes the id of a case that does not use it. Append every new key here.
struct LateKey {
  const char* key;
  const char* old_behaviour;  ///< the value as JSON text
};
constexpr std::array<LateKey, 1> kLateKeys{{{"numerics.sampling", "\"kernel\""}}};
}  // namespace

std::string case_id(const CaseParams& p) {
  nlohmann::json j = to_json(p);
  for (const auto& key : case_key_names(p.scene))
    if (is_output_only_key(key)) {
      const auto ptr = pointer_of(key);
      if (j.contains(ptr)) j.at(ptr.parent_pointer()).erase(ptr.back());
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
