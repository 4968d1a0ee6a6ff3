#pragma once
// Study files (design brief section 7): a base case, groups that override it, and a [matrix]
// (cartesian product) and [zip] (lists zipped) expanded within every group. Every expanded case
// is validated and identified by case_id() of its fully resolved parameters, so that renaming or
// reordering a study never reruns a finished case.
#include <string>
#include <utility>
#include <vector>

#include "core/case_params.hpp"

namespace boycott::driver {

struct StudyCase {
  std::string group;
  std::string id;  ///< case_id(params)
  CaseParams params;
  /// The keys set by the group, the matrix and the zip, with their values as TOML text.
  std::vector<std::pair<std::string, std::string>> swept;
};

struct Study {
  std::string name;
  std::string source_text;          ///< the study file as read, stored in the database
  std::vector<std::string> groups;  ///< in file order
  std::vector<StudyCase> cases;     ///< group by group, matrix x zip within each
};

/// Parses and expands a study; every error (malformed TOML, unknown key, bad value, unequal zip
/// lengths, two cases with one id) is an InputError naming the key.
Study expand_study_string(const std::string& toml_text, const std::string& origin = "<string>");
Study expand_study_file(const std::string& path);

/// The case as a TOML case file (what `boycott case run` reads); parsing it gives the same id.
std::string case_to_toml(const CaseParams& p);

}  // namespace boycott::driver
