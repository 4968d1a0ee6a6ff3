#include "driver/store/store.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"

namespace boycott::driver {

namespace {
std::string hostname() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}
std::string program_version() {
  return fmt::format("{}+{}", kVersion, kGitRevision);
}
std::optional<double> number_of(const std::string& toml_value) {
  char* end = nullptr;
  const double v = std::strtod(toml_value.c_str(), &end);
  if (end == toml_value.c_str() || *end != '\0') return std::nullopt;
  return v;
}
std::optional<double> json_number(const nlohmann::json& j, const char* key) {
  if (j.contains(key) && j[key].is_number()) return j[key].get<double>();
  return std::nullopt;
}
}  // namespace

void register_study(Database& db, const Study& s) {
  db.transaction([&] {
    const auto now = utc_now();
    db.prepare(
          "INSERT INTO studies(name, source_toml, created_at, updated_at) VALUES (?1, ?2, ?3, ?3) "
          "ON CONFLICT(name) DO UPDATE SET source_toml = excluded.source_toml, updated_at = "
          "excluded.updated_at")
        .bind(1, s.name)
        .bind(2, s.source_text)
        .bind(3, now)
        .run();
    // Membership follows the study file as it is now (groups may have been renamed).
    db.prepare("DELETE FROM study_cases WHERE study = ?1").bind(1, s.name).run();
    std::int64_t pos = 0;
    for (const auto& c : s.cases) write_case_rows(db, s.name, c, pos++, now);
  });
}

void write_case_rows(Database& db, const std::string& study, const StudyCase& c,
                     std::optional<std::int64_t> position, const std::string& now) {
  // The same case may come back with a raised time.end (not part of its identity): the stored
  // parameters follow the study, so that a result short of the new end is no longer done.
  db.prepare(
        "INSERT INTO cases(id, scene, angle_deg, params_json, created_at) VALUES (?1,?2,?3,?4,?5) "
        "ON CONFLICT(id) DO UPDATE SET params_json = excluded.params_json")
      .bind(1, c.id)
      .bind(2, c.params.scene)
      .bind(3, c.params.gravity.angle_deg)
      .bind(4, to_json(c.params).dump())
      .bind(5, now)
      .run();
  db.prepare(
        "INSERT OR IGNORE INTO study_cases(study, group_name, case_id, position) VALUES (?1, ?2, ?3, "
        "IFNULL(?4, (SELECT IFNULL(MAX(position), -1) + 1 FROM study_cases WHERE study = ?1)))")
      .bind(1, study)
      .bind(2, c.group)
      .bind(3, c.id)
      .bind(4, position)
      .run();
  for (const auto& [k, v] : c.swept)
    db.prepare("INSERT OR IGNORE INTO case_values(case_id, key, value, value_num) VALUES (?1,?2,?3,?4)")
        .bind(1, c.id)
        .bind(2, k)
        .bind(3, v)
        .bind(4, number_of(v))
        .run();
}

std::int64_t begin_attempt(Database& db, const std::string& case_id, int ranks, const std::string& run_dir) {
  std::int64_t id = 0;
  db.transaction([&] {
    const auto now = utc_now();
    db.prepare(
          "UPDATE attempts SET ended_at = ?2, error_text = 'abandoned: the driver stopped without recording "
          "an "
          "end' WHERE case_id = ?1 AND ended_at IS NULL")
        .bind(1, case_id)
        .bind(2, now)
        .run();
    db.prepare(
          "INSERT INTO attempts(case_id, started_at, host, ranks, program_version, run_dir) "
          "VALUES (?1, ?2, ?3, ?4, ?5, ?6)")
        .bind(1, case_id)
        .bind(2, now)
        .bind(3, hostname())
        .bind(4, ranks)
        .bind(5, program_version())
        .bind(6, run_dir)
        .run();
    auto st = db.prepare("SELECT last_insert_rowid()");
    st.step();
    id = st.integer(0);
  });
  return id;
}

void finish_attempt(Database& db, std::int64_t attempt, int exit_status, const std::string& error_text) {
  db.transaction([&] {
    db.prepare("UPDATE attempts SET ended_at = ?2, exit_status = ?3, error_text = ?4 WHERE id = ?1")
        .bind(1, attempt)
        .bind(2, utc_now())
        .bind(3, exit_status)
        .bind(4, error_text)
        .run();
  });
}

bool update_result_summary(Database& db, const std::string& case_id, const nlohmann::json& summary) {
  bool updated = false;
  db.transaction([&] {
    db.prepare("UPDATE results SET settling_velocity_stderr_m_s = ?2, summary_json = ?3 WHERE case_id = ?1")
        .bind(1, case_id)
        .bind(2, json_number(summary, "settling_velocity_stderr_m_s"))
        .bind(3, summary.dump())
        .run();
    auto st = db.prepare("SELECT changes()");
    st.step();
    updated = st.integer(0) > 0;
  });
  return updated;
}

void record_result(Database& db, std::int64_t attempt, const std::string& case_id,
                   const nlohmann::json& summary) {
  nlohmann::json errors = nlohmann::json::object();
  for (const auto& [k, v] : summary.items())
    // The scene's errors against its reference; not the statistics of <<w_p>> (settling_velocity_*,
    // warnings) nor the run's precision target (target_*).
    if (k.find("error") != std::string::npos && k.rfind("settling_velocity_", 0) != 0 &&
        k.rfind("target_", 0) != 0)
      errors[k] = v;
  const auto params = summary.contains("params") ? summary["params"] : nlohmann::json();
  db.transaction([&] {
    const auto now = utc_now();
    db.prepare("UPDATE attempts SET ended_at = ?2, exit_status = 0, error_text = NULL WHERE id = ?1")
        .bind(1, attempt)
        .bind(2, now)
        .run();
    // The averaging window from the case itself, where the summary does not say which it used.
    auto pst = db.prepare("SELECT params_json FROM cases WHERE id = ?1");
    pst.bind(1, case_id);
    std::optional<double> from, to;
    if (pst.step()) {
      // Scenes that do not average have no time.average_from (and channel_flow no window at all).
      const auto p = nlohmann::json::parse(pst.text(0));
      if (auto f = json_number(p.value("time", nlohmann::json::object()), "average_from")) from = f;
      if (auto e = json_number(p.value("time", nlohmann::json::object()), "end")) to = e;
    }
    if (auto t = json_number(summary, "simulated_time_s")) to = t;
    // The window the run used: its own choice where time.average_from = "auto".
    if (auto f = json_number(summary, "average_from_s")) from = f;
    std::optional<std::int64_t> steps;
    if (summary.contains("particle_steps") && summary["particle_steps"].is_number())
      steps = summary["particle_steps"].get<std::int64_t>();
    db.prepare(
          "INSERT OR REPLACE INTO results(case_id, attempt_id, mean_settling_velocity_m_s, "
          "settling_velocity_stderr_m_s, average_from_s, average_to_s, wall_time_s, particle_steps, "
          "validation_errors_json, summary_json, recorded_at) VALUES (?1,?2,?3,?4,?5,?6,?7,?8,?9,?10,?11)")
        .bind(1, case_id)
        .bind(2, attempt)
        .bind(3, json_number(summary, "mean_settling_velocity_m_s"))
        .bind(4, json_number(summary, "settling_velocity_stderr_m_s"))
        .bind(5, from)
        .bind(6, to)
        .bind(7, json_number(summary, "wall_time_s"))
        .bind(8, steps)
        .bind(9, errors.dump())
        .bind(10, summary.dump())
        .bind(11, now)
        .run();
    // Test hook: widens the window in which a kill -9 lands inside this transaction.
    if (const char* d = std::getenv("BOYCOTT_TEST_COMMIT_DELAY_S"))
      std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(d)));
  });
}

namespace {
/// Whether a run's summary (S, JSON text) reached its case's time.end as the study now sets it
/// (P, the case's params_json), or met the precision target the study now asks for: the case is
/// done. A case without an end (ergun) or a summary without its time counts as done.
std::string reaches_end_sql(const std::string& S, const std::string& P) {
  return fmt::format(
      "(json_extract({P}, '$.time.end') IS NULL OR json_extract({S}, '$.simulated_time_s') IS NULL OR "
      "reached_end(json_extract({S}, '$.simulated_time_s'), json_extract({P}, '$.time.end')) OR "
      "(json_extract({S}, '$.status') = 'converged' AND "
      "IFNULL(json_extract({P}, '$.time.target_rel_error'), 0) >= json_extract({S}, '$.target_rel_error')))",
      fmt::arg("S", S), fmt::arg("P", P));
}
const std::string kResultReachesEnd = reaches_end_sql("r.summary_json", "c.params_json");
}  // namespace

bool summary_reaches_end(Database& db, const std::string& case_id, const std::string& summary_json) {
  auto st = db.prepare("SELECT " + reaches_end_sql("?2", "params_json") + " FROM cases WHERE id = ?1");
  st.bind(1, case_id);
  st.bind(2, summary_json);
  // A case the database does not hold has no end to compare with.
  return !st.step() || st.is_null(0) || st.integer(0) != 0;
}

bool result_reaches_end(Database& db, const std::string& case_id, const std::string& params_json) {
  auto st = db.prepare("SELECT 1 FROM results r WHERE r.case_id = ?1 AND " +
                       reaches_end_sql("r.summary_json", "?2"));
  st.bind(1, case_id);
  st.bind(2, params_json);
  return st.step();
}

bool has_result(Database& db, const std::string& case_id) {
  auto st = db.prepare("SELECT 1 FROM results r JOIN cases c ON c.id = r.case_id WHERE r.case_id = ?1 AND " +
                       kResultReachesEnd);
  st.bind(1, case_id);
  return st.step();
}

std::optional<double> result_settling_velocity(Database& db, const std::string& case_id) {
  auto st = db.prepare("SELECT mean_settling_velocity_m_s FROM results WHERE case_id = ?1");
  st.bind(1, case_id);
  if (!st.step() || st.is_null(0)) return std::nullopt;
  return st.real(0);
}

const char* to_string(CaseStatus s) {
  switch (s) {
    case CaseStatus::kPending:
      return "pending";
    case CaseStatus::kRunning:
      return "running";
    case CaseStatus::kDone:
      return "done";
    case CaseStatus::kFailed:
      return "failed";
    case CaseStatus::kInterrupted:
      return "interrupted";
  }
  return "?";
}

std::vector<CaseState> case_states(Database& db, const std::string& study, int retries) {
  std::vector<CaseState> out;
  auto st = db.prepare(
      "SELECT sc.study, sc.group_name, c.id, c.angle_deg, "
      " EXISTS(SELECT 1 FROM results r WHERE r.case_id = c.id AND " +
      kResultReachesEnd +
      "), "
      " (SELECT COUNT(*) FROM attempts a WHERE a.case_id = c.id AND a.exit_status IS NOT NULL "
      "    AND a.exit_status NOT IN (0, 74, 75, 130, 138, 143)), "
      " (SELECT COUNT(*) FROM attempts a WHERE a.case_id = c.id AND a.exit_status = 2 "
      "    AND a.program_version = ?2), "
      " EXISTS(SELECT 1 FROM attempts a WHERE a.case_id = c.id AND a.ended_at IS NULL), "
      " (SELECT a.exit_status FROM attempts a WHERE a.case_id = c.id AND a.ended_at IS NOT NULL ORDER BY "
      "a.id DESC "
      "    LIMIT 1), "
      " (SELECT a.error_text FROM attempts a WHERE a.case_id = c.id AND a.ended_at IS NOT NULL ORDER BY a.id "
      "DESC "
      "    LIMIT 1), "
      " (SELECT a.ranks FROM attempts a WHERE a.case_id = c.id ORDER BY a.id DESC LIMIT 1) "
      "FROM study_cases sc JOIN cases c ON c.id = sc.case_id "
      "WHERE (?1 = '' OR sc.study = ?1) ORDER BY sc.study, sc.position");
  // A case the solver refused as bad input is final only for this program version: a newer solver
  // (one that implements the scene, say) gets to try it again.
  st.bind(1, study).bind(2, program_version());
  while (st.step()) {
    CaseState c;
    c.study = st.text(0);
    c.group = st.text(1);
    c.id = st.text(2);
    c.angle_deg = st.real(3);
    const bool done = st.integer(4) != 0;
    c.failures = static_cast<int>(st.integer(5));
    c.input_error = st.integer(6) > 0;
    const bool open = st.integer(7) != 0;
    c.last_exit = st.is_null(8) ? -1 : static_cast<int>(st.integer(8));
    c.last_error = st.text(9);
    c.ranks = st.is_null(10) ? 0 : static_cast<int>(st.integer(10));
    if (done)
      c.status = CaseStatus::kDone;
    else if (open)
      c.status = CaseStatus::kRunning;
    else if (c.input_error || c.failures > retries)
      c.status = CaseStatus::kFailed;
    else if (c.last_exit == 75 || c.last_exit == 130 || c.last_exit == 138 || c.last_exit == 143)
      c.status = CaseStatus::kInterrupted;
    else
      c.status = CaseStatus::kPending;
    out.push_back(std::move(c));
  }
  return out;
}

std::string SweptValue::display() const {
  return value_num ? fmt::format("{:.6g}", *value_num) : value;
}

std::vector<SweptValue> case_swept_values(Database& db, const std::string& case_id) {
  auto st = db.prepare("SELECT key, value, value_num FROM case_values WHERE case_id = ?1 ORDER BY key");
  st.bind(1, case_id);
  std::vector<SweptValue> out;
  while (st.step()) {
    SweptValue v{st.text(0), st.text(1), std::nullopt};
    if (!st.is_null(2)) v.value_num = st.real(2);
    out.push_back(std::move(v));
  }
  return out;
}

std::optional<std::string> study_source(Database& db, const std::string& study) {
  auto st = db.prepare("SELECT source_toml FROM studies WHERE name = ?1");
  st.bind(1, study);
  if (!st.step()) return std::nullopt;
  return st.text(0);
}

std::vector<CurveResult> curve_results(Database& db, const std::string& study, const std::string& group) {
  // Runs whose summary names no error method predate the autocorrelation estimate: batch means.
  auto st = db.prepare(
      "SELECT sc.group_name, c.id, c.angle_deg, r.mean_settling_velocity_m_s, "
      "r.settling_velocity_stderr_m_s, "
      " MIN(sc.position) AS pos, "
      " COALESCE(json_extract(r.summary_json, '$.settling_velocity_error_method'), 'batch_means'), "
      " json_extract(r.summary_json, '$.settling_velocity_error_dof'), "
      " json_extract(r.summary_json, '$.particle_count'), r.average_from_s, r.average_to_s "
      "FROM study_cases sc JOIN cases c ON c.id = sc.case_id "
      "JOIN results r ON r.case_id = c.id WHERE sc.study = ?1 AND (?2 = '' OR sc.group_name = ?2) "
      "AND r.mean_settling_velocity_m_s IS NOT NULL GROUP BY sc.group_name, c.id");
  st.bind(1, study).bind(2, group);
  std::vector<CurveResult> out;
  while (st.step()) {
    CurveResult r;
    r.group = st.text(0);
    r.case_id = st.text(1);
    r.angle_deg = st.real(2);
    r.w_m_s = st.real(3);
    if (!st.is_null(4)) r.w_err_m_s = st.real(4);
    r.position = st.integer(5);
    r.error_method = st.text(6);
    if (!st.is_null(7)) r.error_dof = st.real(7);
    if (!st.is_null(8)) r.n_particles = st.integer(8);
    if (!st.is_null(9)) r.average_from_s = st.real(9);
    if (!st.is_null(10)) r.end_s = st.real(10);
    out.push_back(std::move(r));
  }
  return out;
}

void require_study(Database& db, const std::string& study) {
  auto st = db.prepare("SELECT COUNT(*) FROM studies WHERE name = ?1");
  st.bind(1, study);
  st.step();
  if (st.integer(0) == 0) throw InputError(fmt::format("no study '{}' in '{}'", study, db.path()));
}

std::vector<std::string> study_groups(Database& db, const std::string& study) {
  auto st = db.prepare(
      "SELECT group_name FROM study_cases WHERE study = ?1 GROUP BY group_name ORDER BY MIN(position)");
  st.bind(1, study);
  std::vector<std::string> groups;
  while (st.step()) groups.push_back(st.text(0));
  return groups;
}

std::vector<StoredResult> stored_results(Database& db, const std::string& study) {
  // LEFT JOIN: without a study filter, a result whose case left every study still shows.
  auto st = db.prepare(
      "SELECT sc.study, sc.group_name, c.id, c.scene, r.mean_settling_velocity_m_s, r.wall_time_s, "
      "r.validation_errors_json FROM results r JOIN cases c ON c.id = r.case_id "
      "LEFT JOIN study_cases sc ON sc.case_id = c.id WHERE (?1 = '' OR sc.study = ?1) "
      "ORDER BY sc.study IS NULL, sc.study, sc.position, c.id");
  st.bind(1, study);
  std::vector<StoredResult> out;
  while (st.step()) {
    StoredResult r;
    if (!st.is_null(0)) r.study = st.text(0);
    if (!st.is_null(1)) r.group = st.text(1);
    r.case_id = st.text(2);
    r.scene = st.text(3);
    if (!st.is_null(4)) r.w_m_s = st.real(4);
    if (!st.is_null(5)) r.wall_time_s = st.real(5);
    if (!st.is_null(6)) r.validation_errors_json = st.text(6);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<SettlingResult> settling_results(Database& db, const std::string& study) {
  auto st = db.prepare(
      "SELECT sc.group_name, c.id, c.angle_deg, r.mean_settling_velocity_m_s, "
      "r.settling_velocity_stderr_m_s, "
      "r.wall_time_s, r.particle_steps FROM study_cases sc JOIN cases c ON c.id = sc.case_id "
      "JOIN results r ON r.case_id = c.id WHERE sc.study = ?1 AND r.mean_settling_velocity_m_s IS NOT NULL "
      "ORDER BY sc.position");
  st.bind(1, study);
  std::vector<SettlingResult> out;
  while (st.step()) {
    SettlingResult r{st.text(0),
                     st.text(1),
                     st.real(2),
                     st.real(3),
                     st.is_null(4) ? std::numeric_limits<double>::quiet_NaN() : st.real(4),
                     std::nullopt,
                     std::nullopt};
    if (!st.is_null(5)) r.wall_time_s = st.real(5);
    if (!st.is_null(6)) r.particle_steps = st.integer(6);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<RunRecord> run_records(Database& db, const std::string& study) {
  auto st = db.prepare(
      "SELECT sc.group_name, c.id, c.angle_deg, MIN(sc.position) AS pos, "
      " json_extract(r.summary_json, '$.particle_count'), r.average_from_s, r.average_to_s, "
      " r.mean_settling_velocity_m_s, json_extract(r.summary_json, '$.settling_velocity_error_m_s'), "
      " json_extract(r.summary_json, '$.settling_velocity_error_method'), "
      " json_extract(r.summary_json, '$.settling_velocity_error_dof'), "
      " json_extract(r.summary_json, '$.settling_velocity_correlation_time_s'), "
      " json_extract(r.summary_json, '$.settling_velocity_window_correlation_times'), r.wall_time_s, "
      " json_extract(r.summary_json, '$.mpi_ranks'), json_extract(r.summary_json, '$.cpu_time_s') "
      "FROM study_cases sc JOIN cases c ON c.id = sc.case_id JOIN results r ON r.case_id = c.id "
      "WHERE sc.study = ?1 GROUP BY sc.group_name, c.id ORDER BY pos, c.id");
  st.bind(1, study);
  std::vector<RunRecord> out;
  const auto real = [&](int col) {
    return st.is_null(col) ? std::nullopt : std::optional<double>(st.real(col));
  };
  const auto integer = [&](int col) {
    return st.is_null(col) ? std::nullopt : std::optional<std::int64_t>(st.integer(col));
  };
  while (st.step()) {
    RunRecord r;
    r.group = st.text(0);
    r.case_id = st.text(1);
    r.angle_deg = st.real(2);
    r.n_particles = integer(4);
    r.average_from_s = real(5);
    r.end_s = real(6);
    r.w_m_s = real(7);
    r.error_m_s = real(8);
    if (!st.is_null(9)) r.error_method = st.text(9);
    r.error_dof = real(10);
    r.correlation_time_s = real(11);
    r.window_correlation_times = real(12);
    r.wall_time_s = real(13);
    r.ranks = integer(14);
    r.cpu_time_s = real(15);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<FinishedCost> finished_costs(Database& db) {
  std::vector<FinishedCost> out;
  auto st = db.prepare(
      "SELECT c.id, c.params_json, r.summary_json FROM results r JOIN cases c ON c.id = r.case_id "
      "WHERE r.wall_time_s IS NOT NULL ORDER BY c.id");
  while (st.step()) out.push_back({st.text(0), st.text(1), st.text(2)});
  return out;
}

}  // namespace boycott::driver
