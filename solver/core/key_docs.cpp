#include "core/key_docs.hpp"

#include <algorithm>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/case_key_table.hpp"

namespace boycott {

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string_view last_part(std::string_view key) {
  const auto dot = key.rfind('.');
  return dot == std::string_view::npos ? key : key.substr(dot + 1);
}
}  // namespace

std::string did_you_mean(std::string_view key) {
  std::string_view best;
  std::size_t best_d = std::max<std::size_t>(2, key.size() / 5) + 1;
  const auto names = case_key_names();
  for (const auto& name : names) {
    // The right name in the wrong section ("time.viscosity") counts as one edit.
    const std::size_t dist = last_part(name) == last_part(key) ? 1 : edit_distance(key, name);
    if (dist < best_d) best_d = dist, best = name;
  }
  return best.empty() ? "" : " (did you mean '" + std::string(best) + "'?)";
}

std::optional<KeyDoc> key_doc(std::string_view key) {
  std::optional<KeyDoc> doc;
  const CaseParams defaults;
  case_keys::visit_keys(defaults, [&](const char* name, const auto& member, const case_keys::Rule& rule) {
    if (name != key) return;
    using T = std::decay_t<decltype(member)>;
    // A name or a flag has no unit; a number without one is a pure number.
    const bool word = std::is_same_v<T, std::string> || std::is_same_v<T, bool> || !rule.choices.empty();
    std::string meaning = rule.doc;
    if (!rule.choices.empty()) meaning += fmt::format("; one of {}", fmt::join(rule.choices, ", "));
    doc = KeyDoc{name, *rule.unit ? rule.unit : (word ? "" : "-"), meaning};
  });
  return doc;
}

}  // namespace boycott
