#pragma once
// The results_schema/NNN_*.sql files, embedded at build time (results_schema/embed.cmake).
#include <string>
#include <vector>

namespace boycott::driver {

struct SchemaFile {
  std::string name;  ///< e.g. "001_initial.sql"; the number is the schema version it leads to
  std::string sql;
};

/// In version order; file i brings the database to user_version i + 1.
const std::vector<SchemaFile>& schema_files();

}  // namespace boycott::driver
