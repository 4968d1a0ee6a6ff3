#pragma once
// A case key set from a TOML value as the parser holds it: a study's [base], [group.set],
// [matrix] and [zip] values reach the case as data, never written back to text and read again.
#include <string>

#include <toml++/toml.h>

#include "core/case_params.hpp"

namespace boycott {

/// A case from a parsed TOML table (a case file's, or a study's [base]): every key not in it at
/// its default, unvalidated. InputError for an unknown key or a wrong type, naming the key.
CaseParams case_from_toml(const toml::table& tbl);

/// Sets `key` (dotted) to `value`, as a case file line or a --set would: the key becomes one the
/// user set, and a particles.count replaces a particles.volume_fraction (and the other way
/// round). InputError for an unknown key or a value of the wrong type, naming the key.
void apply_value(CaseParams& p, const std::string& key, const toml::node& value);

}  // namespace boycott
