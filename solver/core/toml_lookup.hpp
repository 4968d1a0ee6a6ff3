#pragma once
// Finding where a dotted case key is written in a parsed TOML file, so that an error in its value
// can name the line: `fluid.viscosity = 1` in [fluid], `viscosity` under [fluid], or the quoted
// `"fluid.viscosity" = 1` that studies use in their [matrix] and [zip] tables.
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <toml++/toml.h>

namespace boycott {

/// The node that `dotted` names in `t`, however its parts are split between tables and quoted
/// keys; nullptr where none does.
inline const toml::node* find_dotted(const toml::table& t, std::string_view dotted) {
  if (const toml::node* n = t.get(dotted)) return n;
  for (std::size_t dot = dotted.find('.'); dot != std::string_view::npos; dot = dotted.find('.', dot + 1))
    if (const auto* sub = t.get_as<toml::table>(dotted.substr(0, dot)))
      if (const toml::node* n = find_dotted(*sub, dotted.substr(dot + 1))) return n;
  return nullptr;
}

/// "origin:line: " for a node read from a file; "" for none.
inline std::string line_prefix(const toml::node* n, const std::string& origin) {
  if (!n || !n->source().begin) return "";
  return fmt::format("{}:{}: ", origin, n->source().begin.line);
}

}  // namespace boycott
