#pragma once
// Readable names for the run folders: beside FILE.runs/<case_id>/, the tree FILE.names/<study>/
// <group>/<key>=<value>/.../ (one component per varied key, then replica=<k> where the group
// runs replicas)
// whose leaves are relative links to the case's run folder. Kept up to date by `study run` and
// `study collect`; a convenience view: failing to write it never fails a study.
#include <filesystem>
#include <string>

#include "driver/study/study.hpp"

namespace boycott::driver {

/// The folder where the cases of the database at db_path run: <db_path>.runs/<case_id>/.
std::string runs_root(const std::string& db_path);

/// The folder of the tree for the database at db_path: "<db_path>.names".
std::filesystem::path names_root(const std::string& db_path);
/// The leaf of one case, relative to names_root.
std::filesystem::path case_name_path(const Study& study, const StudyCase& c);
/// Writes (or corrects) the links of every case of the study; returns how many could not be.
int update_run_tree(const Study& study, const std::string& db_path, const std::filesystem::path& runs_root);

}  // namespace boycott::driver
