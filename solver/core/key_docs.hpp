#pragma once
// Unit and one line of meaning for every case key, for `boycott case keys` (and its JSON). A test
// checks that every name of case_key_names() has an entry here, so a new key cannot go undocumented.
#include <optional>
#include <string>
#include <string_view>

namespace boycott {

struct KeyDoc {
  std::string_view key;
  std::string_view unit;  ///< SI unit, "-" for a pure number, "" for a name or a flag
  std::string_view meaning;
};

/// The entry of a dotted key ("time.dt_dem"); empty when there is none.
std::optional<KeyDoc> key_doc(std::string_view key);

/// For an unknown key: " (did you mean 'fluid.viscosity'?)" when a known key is a few edits away
/// (or has the same last part in another section), else "".
std::string did_you_mean(std::string_view key);

}  // namespace boycott
