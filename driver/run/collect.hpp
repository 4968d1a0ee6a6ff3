#pragma once
// `boycott study collect`: the one writer of the study database for cases that ran elsewhere
// (Slurm array tasks, slurm.hpp). Tasks write only their run folders, <db>.runs/<case_id>/: each
// attempt's record (attempts/*.json, written atomically at its start and again at its end) and
// the solver's outputs (summary.json written atomically at the end). Collect copies them into the
// database from one host: one attempt row per record (matched by file name, so running it again
// adds nothing), each ended attempt recorded as `study run` records it (recording.hpp), a finished
// summary.json of the case as its result. A folder still being written is safe to read: a record
// without an end stays an open attempt, and a summary counts only with a finished status and this
// case's id. An open attempt whose job squeue no longer lists is closed as abandoned.
#include <filesystem>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

struct CollectResult {
  int results = 0;    ///< results recorded from finished run folders
  int attempts = 0;   ///< attempt ends recorded from the tasks' records
  int abandoned = 0;  ///< open attempts closed: their job left the queue without recording an end
  /// Cases with an open attempt in a Slurm job that is queued or running (or that cannot be
  /// checked: no squeue).
  std::set<std::string> in_slurm;
};

/// Records what the run folders of the study's cases hold and the database does not.
CollectResult collect_run_folders(Database& db, const Study& study, const std::filesystem::path& runs_root);

/// What `study run`, `study submit` and `study collect` do first: case ids of an older identity
/// scheme migrated (run folders renamed), the study registered.
void prepare_study_database(Database& db, const Study& study, const std::filesystem::path& runs_root);

/// <dir>/summary.json where it is what `study collect` would record: a finished run (completed or
/// converged) of case_id that reaches the case's time.end (a run finished at an end since raised
/// is continued by `study run`, not collected); nullopt otherwise.
std::optional<nlohmann::json> collectable_summary(Database& db, const std::filesystem::path& dir,
                                                  const std::string& case_id);

/// `boycott study collect STUDY.toml --db FILE`: exit 0, or 2 on a bad study or database.
int study_collect(const std::string& study_file, const std::string& db_path, int retries);

}  // namespace boycott::driver
