#include "driver/study/study.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "checks/check_case.hpp"
#include "core/case_toml.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/key_docs.hpp"
#include "core/scene_specs.hpp"
#include "core/toml_lookup.hpp"
#include "driver/study/refine.hpp"

namespace boycott::driver {
namespace {

std::string quote(const std::string& s) {
  return nlohmann::json(s).dump();
}

/// A TOML value as people read it (labels, the database's swept values).
std::string toml_text(const toml::node& n) {
  if (auto v = n.value_exact<std::string>()) return quote(*v);
  if (auto v = n.value_exact<std::int64_t>()) return std::to_string(*v);
  if (auto v = n.value_exact<double>()) return fmt::format("{:.17g}", *v);
  if (auto v = n.value_exact<bool>()) return *v ? "true" : "false";
  if (const auto* a = n.as_array()) {
    std::string s = "[";
    for (std::size_t i = 0; i < a->size(); ++i) s += (i ? ", " : "") + toml_text(*a->get(i));
    return s + "]";
  }
  throw InputError("tables cannot be used as values here");
}

/// A value a study sets: the parsed node (applied to the case as it is; it lives as long as the
/// study's parsed table) and its text for people.
struct StudyValue {
  const toml::node* node = nullptr;
  std::string text;
};

StudyValue study_value(const toml::node& n) {
  return {&n, toml_text(n)};
}

/// Flattens {fluid = {viscosity = 1}} and {"fluid.viscosity" = 1} alike into dotted keys.
void flatten(const toml::table& t, const std::string& prefix,
             std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (const auto& [k, node] : t) {
    std::string name = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = node.as_table())
      flatten(*sub, name, out);
    else
      out.emplace_back(name, &node);
  }
}

void check_known_key(const std::string& key, const std::string& where) {
  static const auto names = case_key_names();
  for (const auto& n : names)
    if (n == key) return;
  throw InputError(
      fmt::format("{}: unknown key '{}'{} (see `boycott case keys`)", where, key, did_you_mean(key)), key);
}

/// "origin:line: " of the line that gives `key` its value in the case being expanded: the study's
/// [zip] or [matrix], then the group's, then its [group.set], then [base] (the order they are
/// applied in, latest first); "" where none does (a scene's default, a derived value).
std::string study_key_location(const toml::table& root, const std::string& origin,
                               std::optional<std::size_t> group, const std::string& key) {
  if (key.empty()) return "";
  const toml::table* gt = nullptr;
  if (const auto* ga = root["group"].as_array(); ga && group && *group < ga->size())
    gt = ga->get(*group)->as_table();
  for (const toml::table* t : {&root, gt})
    for (const char* part : {"zip", "matrix", "set"})
      if (const auto* sub = t ? t->get_as<toml::table>(part) : nullptr)
        if (const auto* n = find_dotted(*sub, key)) return line_prefix(n, origin);
  if (const auto* base = root.get_as<toml::table>("base"))
    return line_prefix(find_dotted(*base, key), origin);
  return "";
}

/// One axis of the expansion: the keys it sets, and for each point their TOML values.
struct Axis {
  std::vector<std::string> keys;
  std::vector<std::vector<StudyValue>> points;  ///< points[i][k] is the value of keys[k]
};

std::vector<Axis> read_axes(const toml::table& root) {
  std::vector<Axis> axes;
  if (const auto* m = root["matrix"].as_table()) {
    std::vector<std::pair<std::string, const toml::node*>> entries;
    flatten(*m, "", entries);
    for (const auto& [key, node] : entries) {
      check_known_key(key, "[matrix]");
      const auto* a = node->as_array();
      if (!a || a->empty())
        throw InputError(fmt::format("[matrix] '{}' must be a non-empty list of values", key));
      Axis ax;
      ax.keys = {key};
      for (const auto& e : *a) ax.points.push_back({study_value(e)});
      axes.push_back(std::move(ax));
    }
  } else if (root.contains("matrix")) {
    throw InputError("'matrix' must be a table of lists");
  }
  if (const auto* z = root["zip"].as_table()) {
    std::vector<std::pair<std::string, const toml::node*>> entries;
    flatten(*z, "", entries);
    Axis ax;
    std::size_t len = 0;
    std::string first;
    for (const auto& [key, node] : entries) {
      check_known_key(key, "[zip]");
      const auto* a = node->as_array();
      if (!a || a->empty())
        throw InputError(fmt::format("[zip] '{}' must be a non-empty list of values", key));
      if (ax.keys.empty()) {
        len = a->size();
        first = key;
        ax.points.resize(len);
      } else if (a->size() != len) {
        throw InputError(
            fmt::format("[zip] '{}' has {} values but '{}' has {}: zipped lists must be equally long", key,
                        a->size(), first, len));
      }
      ax.keys.push_back(key);
      for (std::size_t i = 0; i < len; ++i) ax.points[i].push_back(study_value(*a->get(i)));
    }
    if (!ax.keys.empty()) axes.push_back(std::move(ax));
  } else if (root.contains("zip")) {
    throw InputError("'zip' must be a table of lists");
  }
  return axes;
}

bool advance(std::vector<std::size_t>& idx, const std::vector<Axis>& axes) {
  for (std::size_t a = axes.size(); a-- > 0;) {
    if (++idx[a] < axes[a].points.size()) return true;
    idx[a] = 0;
  }
  return false;
}

/// The replica keys of one table (the study's top level or a group), unresolved.
struct ReplicaKeys {
  std::optional<std::int64_t> replicas, max;
  std::optional<double> target_rel_error;
};

// Study and group names become folder names under FILE.names/ and are printed to terminals:
// no "." or "..", no path separator, no NUL or other control character.
void check_name(const std::string& what, const std::string& name) {
  std::string why;
  if (name == "." || name == "..")
    why = "is a folder of its own ('.' or '..')";
  else if (name.find_first_of("/\\") != std::string::npos)
    why = "holds a path separator";
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7f) why = fmt::format("holds the control character {:#04x}", c);
  if (!why.empty())
    throw InputError(fmt::format("{} {:?} {}; names become folder names and terminal text", what, name, why));
}

ReplicaKeys read_replica_keys(const toml::table& t, const std::string& where) {
  ReplicaKeys r;
  auto integer = [&](const char* key, std::int64_t lo) -> std::optional<std::int64_t> {
    const auto* n = t.get(key);
    if (!n) return std::nullopt;
    const auto v = n->value_exact<std::int64_t>();
    if (!v || *v < lo || *v > 1000)
      throw InputError(fmt::format("{}: {} must be a whole number in [{}, 1000]", where, key, lo));
    return v;
  };
  r.replicas = integer("replicas", 1);
  r.max = integer("replicas_max", 2);
  if (const auto* n = t.get("replicas_target_rel_error")) {
    const auto v = n->value<double>();
    if (!v || !(*v > 0.0 && *v < 1.0))
      throw InputError(fmt::format(
          "{}: replicas_target_rel_error must be a number in (0, 1), a fraction of |<<w_p>>|", where));
    r.target_rel_error = v;
  }
  return r;
}

/// A group's plan: its own keys over the study's.
ReplicaPlan resolve_replicas(const ReplicaKeys& study, const ReplicaKeys& group, const std::string& where) {
  ReplicaPlan plan;
  plan.replicas = static_cast<int>(group.replicas.value_or(study.replicas.value_or(1)));
  plan.target_rel_error = group.target_rel_error ? group.target_rel_error : study.target_rel_error;
  const auto max = group.max ? group.max : study.max;
  if (!plan.target_rel_error) {
    if (max)
      throw InputError(fmt::format(
          "{}: replicas_max = {} is the limit of replicas_target_rel_error, which is not set", where, *max));
    plan.max = plan.replicas;
    return plan;
  }
  // Stein's first stage: a scatter from fewer than 3 numbers leaves the t factor at 1.84 and
  // its own size so uncertain that the stage would decide little (stats/point_error.hpp).
  plan.replicas = std::max(plan.replicas, ReplicaPlan::kStageOneMin);
  plan.max = static_cast<int>(max.value_or(std::max(ReplicaPlan::kDefaultReplicasMax, plan.replicas)));
  if (plan.max < plan.replicas)
    throw InputError(fmt::format("{}: replicas_max = {} is below the {} replicas every point starts with",
                                 where, plan.max, plan.replicas));
  return plan;
}

void apply_named(CaseParams& p, const std::string& key, const StudyValue& value, const std::string& where) {
  try {
    apply_value(p, key, *value.node);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()), e.key());
  }
}

}  // namespace

namespace {

/// A [[group]] as the file states it (or the implicit one of a study without groups).
struct Group {
  std::string name;
  std::vector<std::pair<std::string, StudyValue>> sets;
  std::vector<Axis> axes;  ///< the group's own [group.matrix] / [group.zip], before the study's
  ReplicaKeys replicas;
  std::optional<std::size_t> index;  ///< in the file's [[group]] array; none for the implicit one
  bool has_refine_set = false;       ///< values for [refine]'s added points (refine.cpp reads them)
};

/// The [base] table as a case (every key not set there at its default).
CaseParams read_base(const toml::table& root, const std::string& origin) {
  if (root.contains("base") && !root["base"].as_table())
    throw InputError(fmt::format("{}: 'base' must be a table of case keys", origin));
  try {
    const auto* b = root["base"].as_table();
    return case_from_toml(b ? *b : toml::table{});
  } catch (const InputError& e) {
    throw InputError(fmt::format("[base]: {}", e.what()), e.key());
  }
}

Group read_group(const toml::table& gt, std::size_t index, const std::string& origin) {
  Group g;
  g.index = index;
  auto gname = gt["name"].value<std::string>();
  if (!gname || gname->empty()) throw InputError("[[group]]: every group needs a non-empty string 'name'");
  check_name(origin + ": a group's name", *gname);
  g.name = *gname;
  static const std::set<std::string> kGroupKeys = {
      "name", "set", "matrix", "zip", "replicas", "replicas_max", "replicas_target_rel_error", "refine_set"};
  for (const auto& [k, node] : gt) {
    if (!kGroupKeys.count(std::string(k.str())))
      throw InputError(
          fmt::format("group '{}': unknown key '{}' (expected name, set, matrix, zip, replicas, "
                      "replicas_target_rel_error, replicas_max, refine_set)",
                      g.name, k.str()));
  }
  // refine.cpp reads it, with [refine]; a study without [refine] adds no point to set it on.
  g.has_refine_set = gt.contains("refine_set");
  g.replicas = read_replica_keys(gt, fmt::format("group '{}'", g.name));
  // A group may sweep its own keys (one setting varied at a time, as a work-precision study
  // does); they combine with the study's [matrix] as a product.
  try {
    g.axes = read_axes(gt);
  } catch (const InputError& e) {
    throw InputError(fmt::format("group '{}': {}", g.name, e.what()), e.key());
  }
  if (const auto* set = gt["set"].as_table()) {
    std::vector<std::pair<std::string, const toml::node*>> entries;
    flatten(*set, "", entries);
    for (const auto& [key, node] : entries) {
      check_known_key(key, fmt::format("group '{}'", g.name));
      g.sets.emplace_back(key, study_value(*node));
    }
  } else if (gt.contains("set")) {
    throw InputError(fmt::format("group '{}': 'set' must be a table of key = value", g.name));
  }
  return g;
}

/// The [[group]] array; `at_group` follows the group being read.
std::vector<Group> read_groups(const toml::table& root, const std::string& origin,
                               std::optional<std::size_t>& at_group) {
  std::vector<Group> groups;
  if (const auto* ga = root["group"].as_array()) {
    for (const auto& gn : *ga) {
      const auto* gt = gn.as_table();
      if (!gt) throw InputError("[[group]] entries must be tables");
      at_group = groups.size();
      Group g = read_group(*gt, groups.size(), origin);
      for (const auto& other : groups)
        if (other.name == g.name) throw InputError(fmt::format("group '{}' is defined twice", g.name));
      groups.push_back(std::move(g));
    }
  } else if (root.contains("group")) {
    throw InputError("'group' must be an array of tables: [[group]]");
  }
  if (groups.empty()) groups.push_back(Group{"base", {}, {}, {}, std::nullopt});
  at_group.reset();
  return groups;
}

/// Adds a group's cases to the study: its points over the axes (the group's own, then the
/// study's), then its replicas. `seen` (id -> label) refuses two cases that are the same.
void expand_group(Study& s, const Group& g, const CaseParams& base, const std::vector<Axis>& study_axes,
                  const ReplicaPlan& plan, std::map<std::string, std::string>& seen) {
  std::vector<Axis> all = g.axes;
  all.insert(all.end(), study_axes.begin(), study_axes.end());
  const std::string where = fmt::format("group '{}'", g.name);
  const bool replicated = plan.replicas > 1 || plan.target_rel_error.has_value();
  if (replicated)
    for (const auto& ax : all)
      for (const auto& k : ax.keys)
        if (k == "seed")
          throw InputError(fmt::format(
              "{}: replicas = {} runs replica k with seed + k, and the study also varies 'seed' in a "
              "[matrix] or [zip]: vary one or the other",
              where, plan.replicas));
  const std::size_t first = s.cases.size();
  std::vector<std::size_t> idx(all.size(), 0);
  while (true) {
    StudyCase c;
    c.group = g.name;
    c.params = base;
    for (const auto& [k, v] : g.sets) {
      apply_named(c.params, k, v, where);
      c.swept.emplace_back(k, v.text);
    }
    for (std::size_t a = 0; a < all.size(); ++a)
      for (std::size_t k = 0; k < all[a].keys.size(); ++k) {
        apply_named(c.params, all[a].keys[k], all[a].points[idx[a]][k], where);
        c.swept.emplace_back(all[a].keys[k], all[a].points[idx[a]][k].text);
      }
    std::string label = where;
    for (const auto& [k, v] : c.swept) label += fmt::format(" {}={}", k, v);
    try {
      // Completely, pre-flight included: a case that cannot work is refused when the study is
      // read (by every command that reads it), not when its solver starts.
      checks::check_case(c.params);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", label, e.what()), e.key());
    }
    c.id = case_id(c.params);
    c.point_id = c.id;
    if (auto it = seen.find(c.id); it != seen.end())
      throw InputError(fmt::format("{} and {} are the same case {}", it->second, label, c.id));
    seen.emplace(c.id, label);
    s.cases.push_back(std::move(c));
    // Odometer over the axes, last axis fastest.
    if (!advance(idx, all)) break;
  }
  // Replicas after the group's points, replica by replica: the first round gives a whole curve.
  const std::size_t points = s.cases.size() - first;
  for (int k = 1; k < plan.replicas; ++k)
    for (std::size_t i = first; i < first + points; ++i) {
      StudyCase r = [&] {
        try {
          return replica_of(s.cases[i], k);
        } catch (const InputError& e) {
          throw InputError(fmt::format("{}: replicas = {}: {}", where, plan.replicas, e.what()));
        }
      }();
      const std::string label = fmt::format("{} replica {} of case {}", where, k, r.point_id);
      if (auto it = seen.find(r.id); it != seen.end())
        throw InputError(fmt::format("{} and {} are the same case {}", it->second, label, r.id));
      seen.emplace(r.id, label);
      s.cases.push_back(std::move(r));
    }
}

/// Refuses a study of more than kMaxStudyCases cases before any is expanded: one sentence with
/// the count and the limit.
void check_case_count(const std::string& study, const std::vector<Group>& groups,
                      const std::vector<Axis>& axes, const std::map<std::string, ReplicaPlan>& plans) {
  long double total = 0;
  for (const auto& g : groups) {
    long double n = plans.at(g.name).replicas;
    for (const auto* list : {&g.axes, &axes})
      for (const auto& ax : *list) n *= static_cast<long double>(ax.points.size());
    total += n;
  }
  if (total > static_cast<long double>(kMaxStudyCases))
    throw InputError(
        fmt::format("study '{}' expands to {:.0f} cases, more than the {} a study may hold: split it into "
                    "several studies",
                    study, static_cast<double>(total), kMaxStudyCases));
}

/// Whether group g sweeps the refined key; if it does, every key zipped with it must be in
/// refine's set (an added angle needs its own value of them), and max_r_acc needs a 90 deg point.
bool check_refine_axes(const RefinePlan& plan, const Group& g, const std::vector<Axis>& study_axes) {
  for (const auto* list : {&g.axes, &study_axes})
    for (const auto& ax : *list) {
      const auto at = std::find(ax.keys.begin(), ax.keys.end(), plan.key);
      if (at == ax.keys.end()) continue;
      const auto set = plan.set_for(g.name);
      for (const auto& k : ax.keys)
        if (k != plan.key &&
            std::none_of(set.begin(), set.end(), [&](const auto& kv) { return kv.first == k; }))
          throw InputError(
              fmt::format("[refine]: '{}' is zipped with '{}' (group '{}'): give the added points' "
                          "value in [refine] set, or the group's own in its refine_set",
                          k, plan.key, g.name));
      const auto col = static_cast<std::size_t>(at - ax.keys.begin());
      const bool has_90 =
          std::any_of(ax.points.begin(), ax.points.end(), [&](const std::vector<StudyValue>& pt) {
            return pt[col].node->value<double>().value_or(-1.0) == 90.0;
          });
      if (plan.objective == "max_r_acc" && !has_90)
        throw InputError(
            fmt::format("[refine]: objective = \"max_r_acc\" needs a 90 deg point in every curve (r_acc "
                        "divides by it); group '{}' "
                        "has none",
                        g.name));
      return true;
    }
  return false;
}

/// The expansion of a parsed study; `at_group` follows the [[group]] being read or expanded, so
/// that an error in a key's value can be traced to its line.
Study expand_study(const toml::table& root, const std::string& text, const std::string& origin,
                   std::optional<std::size_t>& at_group) {
  static const std::set<std::string> kTopKeys = {
      "name",  "base", "group", "matrix", "zip", "replicas", "replicas_max", "replicas_target_rel_error",
      "refine"};
  for (const auto& [k, node] : root)
    if (!kTopKeys.count(std::string(k.str())))
      throw InputError(
          fmt::format("{}: unknown study key '{}' (expected name, base, group, matrix, zip, replicas, "
                      "replicas_target_rel_error, replicas_max, refine)",
                      origin, k.str()));
  const ReplicaKeys study_replicas = read_replica_keys(root, origin);

  Study s;
  s.source_text = text;
  auto name = root["name"].value<std::string>();
  if (!name || name->empty())
    throw InputError(fmt::format("{}: the study needs a non-empty string 'name'", origin));
  check_name(origin + ": the study's name", *name);
  s.name = *name;
  const CaseParams base = read_base(root, origin);
  const std::vector<Group> groups = read_groups(root, origin, at_group);
  const auto axes = read_axes(root);
  std::map<std::string, std::string> seen;  // id -> "group (values)"
  for (const auto& g : groups)
    s.replica_plans[g.name] = resolve_replicas(study_replicas, g.replicas, fmt::format("group '{}'", g.name));
  check_case_count(s.name, groups, axes, s.replica_plans);
  s.refine = read_refine_plan(text, origin);
  bool refined = false;
  for (const auto& g : groups) {
    at_group = g.index;
    s.groups.push_back(g.name);
    if (g.has_refine_set && !s.refine)
      throw InputError(
          fmt::format("group '{}': refine_set gives values to points [refine] adds; the study has "
                      "no [refine]",
                      g.name));
    if (s.refine) refined = check_refine_axes(*s.refine, g, axes) || refined;
    expand_group(s, g, base, axes, s.replica_plans[g.name], seen);
  }
  if (s.refine && !refined)
    throw InputError(
        fmt::format("[refine]: key '{}' is swept by no group ([matrix] or [zip], the study's or a group's)",
                    s.refine->key));
  return s;
}

toml::table parse_study(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", origin, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}

}  // namespace

Study expand_study_string(const std::string& text, const std::string& origin) {
  const toml::table root = parse_study(text, origin);
  std::optional<std::size_t> at_group;
  try {
    return expand_study(root, text, origin, at_group);
  } catch (const InputError& e) {
    throw InputError(study_key_location(root, origin, at_group, e.key()) + e.what(), e.key());
  }
}

StudyCase replica_of(const StudyCase& replica0, int k) {
  if (replica0.replica != 0) throw std::logic_error("replica_of needs replica 0 of a point");
  const SceneSpec& sc = scene_spec(replica0.params.scene);
  if (!scene_reads(sc, "seed"))
    throw InputError(fmt::format(
        "replicas differ in their seed, which scene {} does not read (its replicas would be one case)",
        sc.name));
  StudyCase c = replica0;
  c.replica = k;
  c.point_id = replica0.id;
  apply_value(c.params, "seed", toml::value<std::int64_t>(replica0.params.seed + k));
  checks::check_case(c.params);
  c.id = case_id(c.params);
  return c;
}

std::string readable_value(const std::string& toml_text) {
  char* end = nullptr;
  const double d = std::strtod(toml_text.c_str(), &end);
  if (end != toml_text.c_str() && *end == '\0' && toml_text.find_first_of(".eE") != std::string::npos)
    return fmt::format("{}", d);
  return toml_text;
}

std::map<std::string, ReplicaPlan> study_replica_plans(const std::string& text, const std::string& origin) {
  const toml::table root = parse_study(text, origin);
  const ReplicaKeys study_replicas = read_replica_keys(root, origin);
  std::optional<std::size_t> at_group;
  std::map<std::string, ReplicaPlan> plans;
  for (const auto& g : read_groups(root, origin, at_group))
    plans[g.name] = resolve_replicas(study_replicas, g.replicas, fmt::format("group '{}'", g.name));
  return plans;
}

Study expand_study_file(const std::string& path) {
  return expand_study_string(read_input_file(path, "study file"), path);
}

std::string case_file_text(const CaseParams& p) {
  return to_json(p).dump(2) + "\n";
}

}  // namespace boycott::driver
