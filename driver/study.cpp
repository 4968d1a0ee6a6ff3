#include "driver/study.hpp"

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/error.hpp"

namespace boycott::driver {
namespace {

std::string quote(const std::string& s) {
  return nlohmann::json(s).dump();
}

/// A TOML value written back as TOML text, for apply_override.
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
  throw InputError(fmt::format("{}: unknown key '{}' (see `boycott case keys`)", where, key));
}

/// One axis of the expansion: the keys it sets, and for each point their TOML values.
struct Axis {
  std::vector<std::string> keys;
  std::vector<std::vector<std::string>> points;  ///< points[i][k] is the value of keys[k]
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
      for (const auto& e : *a) ax.points.push_back({toml_text(e)});
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
      for (std::size_t i = 0; i < len; ++i) ax.points[i].push_back(toml_text(*a->get(i)));
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

void apply_named(CaseParams& p, const std::string& key, const std::string& value, const std::string& where) {
  try {
    apply_override(p, key + "=" + value);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()));
  }
}

}  // namespace

Study expand_study_string(const std::string& text, const std::string& origin) {
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", origin, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
  static const std::set<std::string> kTopKeys = {"name", "base", "group", "matrix", "zip"};
  for (const auto& [k, node] : root)
    if (!kTopKeys.count(std::string(k.str())))
      throw InputError(fmt::format("{}: unknown study key '{}' (expected name, base, group, matrix, zip)",
                                   origin, k.str()));

  Study s;
  s.source_text = text;
  auto name = root["name"].value<std::string>();
  if (!name || name->empty())
    throw InputError(fmt::format("{}: the study needs a non-empty string 'name'", origin));
  s.name = *name;

  std::string base_text;
  if (const auto* b = root["base"].as_table()) {
    std::ostringstream os;
    os << *b;
    base_text = os.str();
  } else if (root.contains("base")) {
    throw InputError(fmt::format("{}: 'base' must be a table of case keys", origin));
  }
  const CaseParams base = [&] {
    try {
      return parse_case_string(base_text, origin + " [base]");
    } catch (const InputError& e) {
      throw InputError(fmt::format("[base]: {}", e.what()));
    }
  }();

  struct Group {
    std::string name;
    std::vector<std::pair<std::string, std::string>> sets;
    std::vector<Axis> axes;  ///< the group's own [group.matrix] / [group.zip], before the study's
  };
  std::vector<Group> groups;
  if (const auto* ga = root["group"].as_array()) {
    for (const auto& gn : *ga) {
      const auto* gt = gn.as_table();
      if (!gt) throw InputError("[[group]] entries must be tables");
      Group g;
      auto gname = (*gt)["name"].value<std::string>();
      if (!gname || gname->empty())
        throw InputError("[[group]]: every group needs a non-empty string 'name'");
      g.name = *gname;
      for (const auto& [k, node] : *gt) {
        if (k.str() != "name" && k.str() != "set" && k.str() != "matrix" && k.str() != "zip")
          throw InputError(
              fmt::format("group '{}': unknown key '{}' (expected name, set, matrix, zip)", g.name, k.str()));
      }
      // A group may sweep its own keys (one setting varied at a time, as a work-precision study
      // does); they combine with the study's [matrix] as a product.
      try {
        g.axes = read_axes(*gt);
      } catch (const InputError& e) {
        throw InputError(fmt::format("group '{}': {}", g.name, e.what()));
      }
      if (const auto* set = (*gt)["set"].as_table()) {
        std::vector<std::pair<std::string, const toml::node*>> entries;
        flatten(*set, "", entries);
        for (const auto& [key, node] : entries) {
          check_known_key(key, fmt::format("group '{}'", g.name));
          g.sets.emplace_back(key, toml_text(*node));
        }
      } else if (gt->contains("set")) {
        throw InputError(fmt::format("group '{}': 'set' must be a table of key = value", g.name));
      }
      for (const auto& other : groups)
        if (other.name == g.name) throw InputError(fmt::format("group '{}' is defined twice", g.name));
      groups.push_back(std::move(g));
    }
  } else if (root.contains("group")) {
    throw InputError("'group' must be an array of tables: [[group]]");
  }
  if (groups.empty()) groups.push_back(Group{"base", {}, {}});

  const auto axes = read_axes(root);
  std::map<std::string, std::string> seen;  // id -> "group (values)"
  for (const auto& g : groups) {
    s.groups.push_back(g.name);
    std::vector<Axis> all = g.axes;
    all.insert(all.end(), axes.begin(), axes.end());
    std::vector<std::size_t> idx(all.size(), 0);
    while (true) {
      StudyCase c;
      c.group = g.name;
      c.params = base;
      const std::string where = fmt::format("group '{}'", g.name);
      for (const auto& [k, v] : g.sets) {
        apply_named(c.params, k, v, where);
        c.swept.emplace_back(k, v);
      }
      for (std::size_t a = 0; a < all.size(); ++a)
        for (std::size_t k = 0; k < all[a].keys.size(); ++k) {
          apply_named(c.params, all[a].keys[k], all[a].points[idx[a]][k], where);
          c.swept.emplace_back(all[a].keys[k], all[a].points[idx[a]][k]);
        }
      std::string label = where;
      for (const auto& [k, v] : c.swept) label += fmt::format(" {}={}", k, v);
      try {
        validate(c.params);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}", label, e.what()));
      }
      c.id = case_id(c.params);
      if (auto it = seen.find(c.id); it != seen.end())
        throw InputError(fmt::format("{} and {} are the same case {}", it->second, label, c.id));
      seen.emplace(c.id, label);
      s.cases.push_back(std::move(c));
      // Odometer over the axes, last axis fastest.
      if (!advance(idx, all)) break;
    }
  }
  return s;
}

Study expand_study_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("cannot read study file '{}'", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return expand_study_string(ss.str(), path);
}

namespace {
std::string json_to_toml_value(const nlohmann::json& v) {
  if (v.is_string()) return v.dump();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
  if (v.is_number()) return fmt::format("{:.17g}", v.get<double>());
  if (v.is_array()) {
    std::string s = "[";
    bool first = true;
    for (const auto& e : v) {
      s += (first ? "" : ", ") + json_to_toml_value(e);
      first = false;
    }
    return s + "]";
  }
  throw InputError("cannot write a nested table as a TOML value");
}
}  // namespace

std::string case_to_toml(const CaseParams& p) {
  const auto j = to_json(p);
  std::string top, sections;
  for (const auto& [k, v] : j.items()) {
    if (v.is_object()) {
      sections += fmt::format("\n[{}]\n", k);
      for (const auto& [k2, v2] : v.items())
        if (!v2.is_null()) sections += fmt::format("{} = {}\n", k2, json_to_toml_value(v2));
    } else if (!v.is_null()) {
      top += fmt::format("{} = {}\n", k, json_to_toml_value(v));
    }
  }
  return top + sections;
}

}  // namespace boycott::driver
