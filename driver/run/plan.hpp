#pragma once
// `boycott study plan`: the cases of a study, their state and their estimated cost, and the
// study's wall time on J jobs of N ranks, from the cost model calibrated on the database's
// finished runs (cost_model.hpp). Runs nothing; reads the database only if it exists.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "driver/run/progress.hpp"
#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

struct PlanOptions {
  std::string study_file;
  std::string db_path;  ///< may not exist
  int jobs = 1;
  int ranks = 1;
  std::string format = "table";  ///< table, csv or json
  /// Also each finished case of the study predicted by a model fitted to the others only.
  bool check_model = false;
  /// The table lists every case even past kListEveryCaseMax (otherwise one line per group).
  bool all = false;
};
/// A table of more cases than this is summarised per group unless PlanOptions::all.
inline constexpr std::size_t kListEveryCaseMax = 10000;
int study_plan(const PlanOptions& opt);

/// What `study run` prints before it starts (cases to run and their estimated wall time), and
/// each case's estimate (its progress display's ETA).
struct PlanEstimate {
  std::string line;
  std::map<std::string, PlannedCase> cases;  ///< by case id
};
/// A case with a run folder under `runs_root` that has reached some time counts only the work
/// from there to its end.
PlanEstimate plan_estimate(Database& db, const Study& study, const std::vector<std::string>& to_run_ids,
                           int jobs, int ranks, const std::filesystem::path& runs_root);

}  // namespace boycott::driver
