#pragma once
// What the driver writes to and reads from the study database; each function that writes is
// one transaction.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "driver/store/database.hpp"
#include "driver/study/study.hpp"

namespace boycott::driver {

/// Inserts the study, its cases and their swept values (existing cases are kept as they are).
void register_study(Database& db, const Study& s);
/// Inside a transaction: the case's row (its parameters updated if it exists), its membership of
/// `study` at `position` (unset: after the study's last) and its swept values.
void write_case_rows(Database& db, const std::string& study, const StudyCase& c,
                     std::optional<std::int64_t> position, const std::string& now);

/// Opens an attempt; closes any attempt of the case left open by a driver that died.
std::int64_t begin_attempt(Database& db, const std::string& case_id, int ranks, const std::string& run_dir);
/// Closes an attempt that produced no result (failure or interruption).
void finish_attempt(Database& db, std::int64_t attempt, int exit_status, const std::string& error_text);
/// Closes the attempt and stores the result from the solver's summary.json, in one transaction.
/// A recorded result's statistics replaced by a recomputed summary (`case summarize`): its error
/// column and summary_json. False when the database holds no result of the case.
bool update_result_summary(Database& db, const std::string& case_id, const nlohmann::json& summary);
void record_result(Database& db, std::int64_t attempt, const std::string& case_id,
                   const nlohmann::json& summary);
/// Whether the case has a result (recorded by any driver on this database).
bool has_result(Database& db, const std::string& case_id);
/// Whether a finished run's summary.json (its text) reached the case's time.end as the stored
/// case now sets it, or met its precision target: a result of it would make the case done.
bool summary_reaches_end(Database& db, const std::string& case_id, const std::string& summary_json);
/// Whether a recorded result of the case reaches the time.end (or precision target) that
/// `params_json` sets: a study file's parameters, which may ask more than those stored.
bool result_reaches_end(Database& db, const std::string& case_id, const std::string& params_json);
/// The case's recorded <<w_p>>; unset without a result or a value.
std::optional<double> result_settling_velocity(Database& db, const std::string& case_id);

enum class CaseStatus { kPending, kRunning, kDone, kFailed, kInterrupted };
const char* to_string(CaseStatus s);

struct CaseState {
  std::string study, group, id;
  double angle_deg = 0;
  CaseStatus status = CaseStatus::kPending;
  int failures = 0;    ///< attempts that ended with a failure exit code
  int last_exit = -1;  ///< -1: none
  std::string last_error;
  bool input_error = false;  ///< an attempt exited 2: retrying cannot help
  int ranks = 0;             ///< MPI ranks of the latest attempt (0: none yet)
};

/// Cases of one study (or all, study empty) with their status; `retries` decides when a failing
/// case counts as failed rather than pending.
std::vector<CaseState> case_states(Database& db, const std::string& study, int retries);

/// A key a study sets on a case (group `set`, matrix, zip), as stored in case_values.
struct SweptValue {
  std::string key;
  std::string value;                ///< TOML text, e.g. 2.0000000000000002e-05 or [200, 6, 100]
  std::optional<double> value_num;  ///< when the value is a number
  bool operator==(const SweptValue& o) const { return key == o.key && value == o.value; }
  /// The value for people: numbers in 6 significant digits (the TOML text keeps all 17).
  std::string display() const;
};

/// The swept values of one case, by key.
std::vector<SweptValue> case_swept_values(Database& db, const std::string& case_id);

/// InputError "no study 'S' in 'FILE'" when the database has no study of that name.
void require_study(Database& db, const std::string& study);

/// The groups of a study in study order (the first position of any of their cases).
std::vector<std::string> study_groups(Database& db, const std::string& study);

/// A recorded result as `query validation` reads it; unset where the column is null.
struct StoredResult {
  std::optional<std::string> study, group;  ///< unset for a case that no study lists any more
  std::string case_id, scene;
  std::optional<double> w_m_s, wall_time_s;
  std::optional<std::string> validation_errors_json;  ///< as stored, not parsed
};

/// Every result, once per study group its case belongs to (and once with no study for a case that
/// none lists), of one study (or all, study empty); by study (none last), position, case id.
std::vector<StoredResult> stored_results(Database& db, const std::string& study);

/// A finished case with a <<w_p>>, as `query curve` reads it: once per study group it belongs to,
/// with its first position in the study.
struct CurveResult {
  std::string group, case_id;
  double angle_deg = 0;
  double w_m_s = 0;                         ///< <<w_p>>
  std::optional<double> w_err_m_s;          ///< its standard error; unset when the run recorded none
  std::int64_t position = 0;                ///< its first position in the study within the group
  std::string error_method;                 ///< settling_velocity_error_method; "batch_means" when none
  std::optional<double> error_dof;          ///< settling_velocity_error_dof
  std::optional<std::int64_t> n_particles;  ///< summary.json particle_count
  /// The run's averaging window (s): where it began (its own choice with average_from = "auto")
  /// and the simulated time it ended at (results.average_from_s, average_to_s).
  std::optional<double> average_from_s, end_s;
};

/// The study's cases with a recorded <<w_p>> (of one group, `group` non-empty), once per group.
std::vector<CurveResult> curve_results(Database& db, const std::string& study, const std::string& group);

/// The study file as last registered (its TOML text); unset when the database has no such study.
std::optional<std::string> study_source(Database& db, const std::string& study);

/// A finished case with a <<w_p>>, as `query work-precision` reads it.
struct SettlingResult {
  std::string group, case_id;
  double angle_deg = 0;
  double w_m_s = 0, w_err_m_s = 0;  ///< <<w_p>> and its standard error (NaN when the run gave none)
  std::optional<double> wall_time_s;
  std::optional<std::int64_t> particle_steps;
};

/// The study's cases with a recorded <<w_p>>, once per group they belong to, in study order.
std::vector<SettlingResult> settling_results(Database& db, const std::string& study);

/// A finished run as `query runs` lists it: its window, its error's basis and its cost, from the
/// summary it recorded (summary.json's keys; unset where a run of an older build wrote none).
struct RunRecord {
  std::string group, case_id;
  double angle_deg = 0;
  std::optional<std::int64_t> n_particles;  ///< particle_count
  std::optional<double> average_from_s, end_s;
  std::optional<double> w_m_s, error_m_s;  ///< <<w_p>> and its covering half-width
  std::optional<std::string> error_method;
  std::optional<double> error_dof, correlation_time_s, window_correlation_times;
  /// Over all its attempts (a resumed run carries its earlier attempts' time in its checkpoint).
  std::optional<double> wall_time_s;
  std::optional<std::int64_t> ranks;  ///< mpi_ranks of the attempt that finished it
  /// CPU core-seconds over all its attempts (cpu_time_s; unset from builds that recorded none).
  std::optional<double> cpu_time_s;
};

/// The study's finished cases, once per group they belong to, in study order.
std::vector<RunRecord> run_records(Database& db, const std::string& study);

/// A finished result's cost, for the cost model of `study plan`: every study's results count.
struct FinishedCost {
  std::string case_id;
  std::string params_json;
  std::string summary_json;
};
std::vector<FinishedCost> finished_costs(Database& db);

}  // namespace boycott::driver
