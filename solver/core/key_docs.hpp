#pragma once
// Unit and one line of meaning of every case key, for `boycott case keys` (and its JSON), read
// from the key table (case_key_table.hpp), where each key is declared once.
#include <optional>
#include <string>
#include <string_view>

namespace boycott {

struct KeyDoc {
  std::string key;
  std::string unit;  ///< SI unit, "-" for a pure number, "" for a name or a flag
  std::string meaning;
};

/// The entry of a dotted key ("time.dt_dem"); empty when there is none.
std::optional<KeyDoc> key_doc(std::string_view key);

/// For an unknown key: " (did you mean 'fluid.viscosity'?)" when a known key is a few edits away
/// (or has the same last part in another section), else "".
std::string did_you_mean(std::string_view key);

}  // namespace boycott
