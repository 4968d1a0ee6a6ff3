// Case values read and written: case files and strings (TOML), the canonical JSON of params.json,
// --set KEY=VALUE; each key's text converted to its member's type, with an error naming the key.
#include <algorithm>
#include <array>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/case_key_table.hpp"
#include "core/case_params.hpp"
#include "core/case_toml.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/key_docs.hpp"
#include "core/scene_specs.hpp"
#include "core/toml_lookup.hpp"

namespace boycott {

namespace case_keys {
/// Splits "a.b" into the JSON pointer "/a/b".
nlohmann::json::json_pointer pointer_of(const std::string& dotted) {
  std::string s = "/" + dotted;
  std::replace(s.begin(), s.end(), '.', '/');
  return nlohmann::json::json_pointer(s);
}

}  // namespace case_keys

using namespace case_keys;

namespace {

// ---- conversions from a generic node (TOML or JSON, through a small adaptor) ----

[[noreturn]] void type_error(const char* key, const char* want, const std::string& got) {
  throw InputError(fmt::format("{} must be {}, got {}", key, want, got), key);
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
void from_toml(const char* key, const toml::node& n, WindowStart& out) {
  if (auto v = n.value_exact<std::string>(); v && *v == "auto") {
    out = WindowStart{0.0, true};
    return;
  }
  if (n.value_exact<double>() || n.value_exact<std::int64_t>()) {
    out = WindowStart{toml_number(key, n), false};
    return;
  }
  type_error(key, "a number or \"auto\"", toml_repr(n));
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
void from_json(const char* key, const nlohmann::json& j, WindowStart& out) {
  if (j.is_string() && j.get<std::string>() == "auto")
    out = WindowStart{0.0, true};
  else if (j.is_number())
    out = WindowStart{j.get<double>(), false};
  else
    type_error(key, "a number or \"auto\"", j.dump());
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
// A number stays the number it was, so that a case giving one keeps its id.
nlohmann::json json_value(const WindowStart& v) {
  return v.automatic ? nlohmann::json("auto") : json_value(v.time_s);
}
template <class T>
nlohmann::json json_value(const T& v) {
  return nlohmann::json(v);
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
      throw InputError(fmt::format("unknown key '{}'{} (see `boycott case keys`)", k, did_you_mean(k)), k);
  }
  return p;
}

/// The line of `origin` that sets `key` in `tbl` ("origin:line: "), or "" where no node of the
/// table holds it (a default, a --set, a key written with quoted dots).
std::string location_in(const toml::table& tbl, const std::string& origin, const std::string& key) {
  return line_prefix(find_dotted(tbl, key), origin);
}

}  // namespace

namespace case_keys {

namespace {
bool set_key(CaseParams& p, const std::string& key, const toml::node& value) {
  bool found = false;
  visit_keys(p, [&](const char* k, auto& ref, const Rule&) {
    if (key == k) {
      from_toml(k, value, ref);
      found = true;
    }
  });
  return found;
}
}  // namespace

bool set_key(CaseParams& p, const std::string& key, const std::string& value) {
  toml::table t;
  try {
    t = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    // A bare word is a string: --set scene=ergun.
    t = toml::parse("v = \"" + value + "\"");
  }
  return set_key(p, key, *t.get("v"));
}

bool is_set_key(const CaseParams& p, const std::string& key) {
  return std::binary_search(p.set_keys.begin(), p.set_keys.end(), key);
}
}  // namespace case_keys

namespace {
toml::table parse_toml(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", origin, src.begin.line, src.begin.column,
                                 e.description()));
  }
}
}  // namespace

CaseParams parse_case_string(const std::string& text, const std::string& origin, bool name_lines) {
  const toml::table tbl = parse_toml(text, origin);
  try {
    return from_toml_table(tbl);
  } catch (const InputError& e) {
    if (e.key().empty() || !name_lines) throw;
    throw InputError(location_in(tbl, origin, e.key()) + e.what(), e.key());
  }
}

std::string case_key_location(const std::string& text, const std::string& origin, const std::string& key) {
  try {
    return location_in(toml::parse(text, origin), origin, key);
  } catch (const toml::parse_error&) {
    return "";
  }
}

CaseParams parse_case_file(const std::string& path) {
  return parse_case_string(read_input_file(path, "case file"), path);
}

namespace {
void collect_json_keys(const nlohmann::json& j, const std::string& prefix, std::vector<std::string>& out) {
  for (const auto& [k, v] : j.items()) {
    const std::string name = prefix.empty() ? k : prefix + "." + k;
    if (v.is_object())
      collect_json_keys(v, name, out);
    else
      out.push_back(name);
  }
}

/// A case in its canonical JSON (a run's params.json, the case.json a study gives its solver):
/// resolved already, so it is checked, not resolved again. A file that is not such a record is
/// refused, naming what is wrong.
CaseParams load_case_json(const std::string& path, const std::string& text,
                          const std::vector<std::string>& overrides) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(fmt::format("{}: malformed JSON: {}", path, e.what()));
  }
  if (!j.is_object() || !j.contains("scene") || !j["scene"].is_string())
    throw InputError(fmt::format("{}: not a case (a JSON case is an object with a string 'scene')", path));
  const auto names = case_key_names();
  const std::set<std::string> known(names.begin(), names.end());
  std::vector<std::string> present;
  collect_json_keys(j, "", present);
  for (const auto& k : present)
    if (!known.count(k) && k != "branch.parent_id" && k != "branch.parent_time_s")
      throw InputError(
          fmt::format("{}: unknown key '{}'{} (see `boycott case keys`)", path, k, did_you_mean(k)), k);
  CaseParams p = case_from_json(j);
  // Every value is explicit in a resolved case: a --set changes that value and nothing derived
  // from it. The one input that only derives another (the count) would be silently ignored.
  for (const auto& s : overrides)
    if (apply_override(p, s) == "particles.volume_fraction")
      throw InputError(fmt::format("--set {}: {} is a resolved case, which gives the count: "
                                   "set particles.count instead",
                                   s, path),
                       "particles.volume_fraction");
  try {
    validate(p);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()), e.key());
  }
  return p;
}
}  // namespace

CaseParams load_case_file(const std::string& path, const std::vector<std::string>& overrides) {
  const std::string text = read_input_file(path, "case file");
  if (path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0)
    return load_case_json(path, text, overrides);
  CaseParams p = parse_case_string(text, path);
  std::set<std::string> set_by_option;
  for (const auto& s : overrides) set_by_option.insert(apply_override(p, s));
  try {
    validate(p);
  } catch (const InputError& e) {
    // The line is named where the file set the value at fault, not where --set did.
    if (e.key().empty() || set_by_option.count(e.key())) throw;
    throw InputError(case_key_location(text, path, e.key()) + e.what(), e.key());
  }
  return p;
}

CaseParams case_from_json(const nlohmann::json& j) {
  CaseParams p;
  visit_keys(p, [&](const char* key, auto& ref, const Rule&) {
    auto ptr = pointer_of(key);
    if (j.contains(ptr)) from_json(key, j.at(ptr), ref);
  });
  // A record of an earlier build lacks the keys added since: it ran with their old behaviour,
  // not with today's default (a key of another scene is set too, and read by nothing).
  for (const auto& late : kLateKeys)
    if (!j.contains(pointer_of(late.key))) set_key(p, late.key, late.old_behaviour);
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
/// What setting `key` by hand means beyond its value: it is the user's (scenes keep defaults
/// for the others), and the particle load is given one way or the other, the later assignment
/// winning (otherwise a count set over a case file's volume_fraction would be silently ignored).
void note_set_key(CaseParams& p, const std::string& key) {
  p.set_keys.insert(std::lower_bound(p.set_keys.begin(), p.set_keys.end(), key), key);
  p.set_keys.erase(std::unique(p.set_keys.begin(), p.set_keys.end()), p.set_keys.end());
  if (key == "particles.count") {
    p.particles.volume_fraction = kUnset;
    p.set_keys.erase(std::remove(p.set_keys.begin(), p.set_keys.end(), "particles.volume_fraction"),
                     p.set_keys.end());
  }
  if (key == "particles.volume_fraction")
    p.set_keys.erase(std::remove(p.set_keys.begin(), p.set_keys.end(), "particles.count"), p.set_keys.end());
}
}  // namespace

std::string apply_override(CaseParams& p, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set '{}': expected key=value", assignment));
  std::string key = assignment.substr(0, eq);
  std::string value = assignment.substr(eq + 1);
  key.erase(key.find_last_not_of(" \t") + 1);
  if (!set_key(p, key, value))
    throw InputError(
        fmt::format("--set: unknown key '{}'{} (see `boycott case keys`)", key, did_you_mean(key)));
  note_set_key(p, key);
  return key;
}

CaseParams case_from_toml(const toml::table& tbl) {
  return from_toml_table(tbl);
}

void apply_value(CaseParams& p, const std::string& key, const toml::node& value) {
  if (!set_key(p, key, value))
    throw InputError(fmt::format("unknown key '{}'{} (see `boycott case keys`)", key, did_you_mean(key)),
                     key);
  note_set_key(p, key);
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

}  // namespace boycott
