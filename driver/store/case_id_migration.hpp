#pragma once
// Case identity version 2 (core/case_params.hpp) for a database and run folders written with an
// earlier scheme: every case id is recomputed from the case's stored parameters, the tables
// that name it follow, and each run folder (<db>.runs/<id>) is renamed, so that `study run`
// reruns nothing that was finished and resumes what was interrupted.
#include <filesystem>
#include <string>

#include "driver/store/database.hpp"

namespace boycott::driver {

struct IdMigration {
  int cases = 0;    ///< case rows whose id changed
  int merged = 0;   ///< cases that became one with another (they differed in output keys only)
  int folders = 0;  ///< run folders renamed
};

/// Brings the database's case ids to kCaseIdVersion, once (a no-op afterwards). Folders are
/// renamed before the database commits, and a rename already done is recognised, so a migration
/// cut short by a kill completes on the next run.
IdMigration migrate_case_ids(Database& db, const std::filesystem::path& runs_root);

}  // namespace boycott::driver
