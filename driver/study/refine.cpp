#include "driver/study/refine.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include "checks/check_case.hpp"
#include "core/case_toml.hpp"
#include "core/error.hpp"
#include "core/key_docs.hpp"

namespace boycott::driver {
namespace {

constexpr const char* kKey = "gravity.angle_deg";

/// The value of a TOML text ("10.0", "[1, 2]") as a node, through a one-line document.
toml::table value_table(const std::string& text) {
  return toml::parse("v = " + text);
}

std::string value_text(const toml::node& n) {
  if (auto v = n.value_exact<double>()) return fmt::format("{:.17g}", *v);
  if (auto v = n.value_exact<std::int64_t>()) return std::to_string(*v);
  if (auto v = n.value_exact<bool>()) return *v ? "true" : "false";
  if (auto v = n.value_exact<std::string>()) return nlohmann::json(*v).dump();
  throw InputError("[refine] set: values must be numbers, booleans or strings");
}

/// A value as the study file gives it, for a refusal: "(none)" where it is missing.
std::string node_text(const toml::node* n) {
  if (!n) return "(none)";
  std::ostringstream out;
  n->visit([&](const auto& v) { out << v; });
  return out.str();
}

/// The keys of a set table (`[refine] set` or a group's `refine_set`, named `where`), flattened.
void read_set(const toml::table& set, const std::string& prefix, const std::string& refined_key,
              const std::string& where, std::vector<std::pair<std::string, std::string>>& out) {
  for (const auto& [k, node] : set) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = node.as_table()) {
      read_set(*sub, key, refined_key, where, out);
      continue;
    }
    const auto names = case_key_names();
    if (std::find(names.begin(), names.end(), key) == names.end())
      throw InputError(fmt::format("{}: unknown key '{}'{}", where, key, did_you_mean(key)), key);
    if (key == refined_key)
      throw InputError(
          fmt::format("{}: '{}' is the key refine chooses; set gives the keys zipped with it", where, key),
          key);
    out.emplace_back(key, value_text(node));
  }
}

/// Each [[group]]'s `refine_set` (study.cpp refuses one in a study without [refine]).
void read_group_sets(const toml::table& root, RefinePlan& plan) {
  const auto* groups = root["group"].as_array();
  if (!groups) return;
  for (const auto& gn : *groups) {
    const auto* gt = gn.as_table();
    const auto name = gt ? (*gt)["name"].value<std::string>() : std::nullopt;
    const auto* node = gt ? gt->get("refine_set") : nullptr;
    if (!node || !name) continue;
    const std::string where = fmt::format("group '{}': refine_set", *name);
    if (!node->as_table()) throw InputError(where + " must be a table of key = value");
    read_set(*node->as_table(), "", plan.key, where, plan.group_set[*name]);
  }
}

RefinePlan read_table(const toml::table& t) {
  static const std::set<std::string> kKeys = {"key", "objective", "resolution", "max_points", "set"};
  for (const auto& [k, node] : t)
    if (!kKeys.count(std::string(k.str())))
      throw InputError(fmt::format(
          "[refine]: unknown key '{}' (expected key, objective, resolution, max_points, set)", k.str()));
  RefinePlan plan;
  const auto key = t["key"].value<std::string>();
  if (!key) throw InputError(fmt::format("[refine]: key = \"{}\" is required", kKey));
  if (*key != kKey)
    throw InputError(
        fmt::format("[refine]: key = \"{}\": refine finds the peak of a curve over the angle, key = \"{}\" "
                    "(r_acc divides by "
                    "the curve's own 90 deg point)",
                    *key, kKey));
  plan.key = *key;
  plan.objective = t["objective"].value_or(std::string("max_abs_settling"));
  if (plan.objective != "max_abs_settling" && plan.objective != "max_r_acc")
    throw InputError(fmt::format("[refine]: objective = \"{}\": use \"max_abs_settling\" or \"max_r_acc\"",
                                 plan.objective));
  const auto res = t["resolution"].value<double>();
  if (!res || !(*res > 0.0) || *res > 90.0)
    throw InputError(fmt::format(
        "[refine]: resolution = {} must be a number of degrees in (0, 90] (the 68 % half-width to find "
        "the peak's angle to)",
        node_text(t.get("resolution"))));
  plan.resolution = *res;
  if (const auto* n = t.get("max_points")) {
    const auto v = n->value_exact<std::int64_t>();
    if (!v || *v < 1 || *v > RefinePlan::kMaxPointsLimit)
      throw InputError(fmt::format("[refine]: max_points = {} must be a whole number in [1, {}]",
                                   node_text(n), RefinePlan::kMaxPointsLimit));
    plan.max_points = static_cast<int>(*v);
  }
  if (const auto* set = t.get("set")) {
    if (!set->as_table()) throw InputError("[refine]: set must be a table of key = value");
    read_set(*set->as_table(), "", plan.key, "[refine] set", plan.set);
  }
  return plan;
}

/// The keys that split a group's curves: besides the refined key and those refine sets, the keys
/// that take two values or more at one angle among its listed cases.
std::set<std::string> splitting_keys(const Study& s, const std::string& group,
                                     const std::vector<const StudyCase*>& listed) {
  std::set<std::string> skip{s.refine->key};
  for (const auto& [k, v] : s.refine->set_for(group)) skip.insert(k);
  std::map<std::string, std::map<double, std::set<std::string>>> values;  // key -> angle -> values
  for (const auto* c : listed)
    for (const auto& [k, v] : c->swept)
      if (!skip.count(k)) values[k][c->params.gravity.angle_deg].insert(v);
  std::set<std::string> out;
  for (const auto& [k, by_angle] : values)
    if (std::any_of(by_angle.begin(), by_angle.end(), [](const auto& a) { return a.second.size() >= 2; }))
      out.insert(k);
  return out;
}

/// A case's curve: "key=value; ..." of the splitting keys, in the order the case sets them.
std::string setting_of(const StudyCase& c, const std::set<std::string>& splitting) {
  std::string label;
  for (const auto& [k, v] : c.swept)
    if (splitting.count(k)) label += fmt::format("{}{}={}", label.empty() ? "" : "; ", k, readable_value(v));
  return label;
}

bool sweeps_key(const StudyCase& c, const std::string& key) {
  return std::any_of(c.swept.begin(), c.swept.end(), [&](const auto& kv) { return kv.first == key; });
}

}  // namespace

std::vector<std::pair<std::string, std::string>> RefinePlan::set_for(const std::string& group) const {
  auto out = set;
  const auto own = group_set.find(group);
  if (own == group_set.end()) return out;
  for (const auto& [k, v] : own->second) {
    const auto at = std::find_if(out.begin(), out.end(), [&](const auto& kv) { return kv.first == k; });
    if (at != out.end())
      at->second = v;
    else
      out.emplace_back(k, v);
  }
  return out;
}

double refined_value(double x, double resolution) {
  const double grid = resolution / 10.0;
  return std::round(x / grid) * grid;
}

std::vector<RefineSeries> refine_series(const Study& s) {
  std::vector<RefineSeries> out;
  if (!s.refine) return out;
  for (const auto& group : s.groups) {
    std::vector<const StudyCase*> listed;
    for (const auto& c : s.cases)
      if (c.group == group && c.refine_round < 0 && c.replica == 0 && sweeps_key(c, s.refine->key))
        listed.push_back(&c);
    if (listed.empty()) continue;
    const auto splitting = splitting_keys(s, group, listed);
    std::map<std::string, std::size_t> index;          // setting -> position in out
    std::map<std::string, std::string> point_setting;  // point id -> setting
    for (const auto* c : listed) {
      const std::string setting = setting_of(*c, splitting);
      if (index.try_emplace(setting, out.size()).second) out.push_back({group, setting, {}, c});
    }
    // Added points share the swept values of the listed case they were made from; replicas join
    // their point's curve.
    for (const auto& c : s.cases)
      if (c.group == group && c.replica == 0 && sweeps_key(c, s.refine->key))
        point_setting[c.id] = setting_of(c, splitting);
    for (const auto& c : s.cases) {
      if (c.group != group) continue;
      const auto it = point_setting.find(c.point_id);
      if (it == point_setting.end()) continue;
      if (const auto at = index.find(it->second); at != index.end()) out[at->second].cases.push_back(&c);
    }
  }
  return out;
}

StudyCase refined_case(const Study& s, const RefineSeries& series, double value, int round) {
  const RefinePlan& plan = *s.refine;
  StudyCase c = *series.first;
  c.refine_round = round;
  c.replica = 0;
  const std::string text = fmt::format("{}", value);
  const std::string where =
      fmt::format("group '{}'{} refined {}={}", series.group,
                  series.setting.empty() ? "" : " (" + series.setting + ")", plan.key, text);
  const auto set = plan.set_for(series.group);
  try {
    apply_value(c.params, plan.key, toml::value<double>(value));
    for (const auto& [k, v] : set) apply_value(c.params, k, *value_table(v).get("v"));
    checks::check_case(c.params);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()), e.key());
  }
  std::map<std::string, std::string> replaced{{plan.key, text}};
  for (const auto& [k, v] : set) replaced[k] = v;
  for (auto& [k, v] : c.swept)
    if (const auto it = replaced.find(k); it != replaced.end()) {
      v = it->second;
      replaced.erase(it);
    }
  for (const auto& [k, v] : set)
    if (replaced.count(k)) c.swept.emplace_back(k, v);
  c.id = case_id(c.params);
  c.point_id = c.id;
  return c;
}

std::optional<RefinePlan> read_refine_plan(const std::string& text, const std::string& origin) {
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: malformed TOML: {}", origin, e.description()));
  }
  const auto* node = root.get("refine");
  if (!node) return std::nullopt;
  const auto* t = node->as_table();
  if (!t) throw InputError(fmt::format("{}: 'refine' must be a table: [refine]", origin));
  RefinePlan plan = read_table(*t);
  read_group_sets(root, plan);
  return plan;
}

}  // namespace boycott::driver
