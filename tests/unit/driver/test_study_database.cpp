#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include <sqlite3.h>
#include "core/run_status.hpp"
#include "stats/distributions.hpp"

#include "driver/report/curve.hpp"
#include "driver/report/curve_query.hpp"
#include "driver/store/database.hpp"
#include "driver/store/schema_files.hpp"
#include "driver/store/store.hpp"
#include "driver/store/store_refine.hpp"
#include "driver/study/refine.hpp"
#include "driver/study/study.hpp"

namespace bd = boycott::driver;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/boycott_dbtest_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::int64_t count(bd::Database& db, const std::string& sql) {
  auto st = db.prepare(sql);
  st.step();
  return st.integer(0);
}

bool has_column(bd::Database& db, const std::string& table, const std::string& col) {
  auto st = db.prepare("SELECT COUNT(*) FROM pragma_table_info('" + table + "') WHERE name = '" + col + "'");
  st.step();
  return st.integer(0) == 1;
}

const char* kStudy = R"(
name = "s"
[base.time]
end = 2.0
average_from = 1.0
[[group]]
name = "a"
[[group]]
name = "b"
set = { "fluid.viscosity" = 2e-3 }
[matrix]
"gravity.angle_deg" = [45, 90]
)";

}  // namespace

TEST(StudyDatabase, SchemaIsCreatedFromResultsSchemaFiles) {
  TempDir d;
  ASSERT_GE(bd::schema_files().size(), 2u);
  EXPECT_EQ(bd::schema_files()[0].name, "001_initial.sql");
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  EXPECT_EQ(db.version(), bd::Database::latest_version());
  for (const char* t : {"studies", "cases", "study_cases", "case_values", "attempts", "results"})
    EXPECT_EQ(
        count(db, std::string("SELECT COUNT(*) FROM sqlite_master WHERE type='table' AND name='") + t + "'"),
        1)
        << t;
  auto st = db.prepare("PRAGMA journal_mode");
  st.step();
  EXPECT_EQ(st.text(0), "wal");
}

// The queries judge "reached time.end" by the SQL function reached_end, which is the C++
// predicate of core/run_status.hpp: the same answer on either side of its tolerance, NULL for NULL.
TEST(StudyDatabase, SqlReachedEndIsTheSolversPredicate) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const double end = 20.0;
  for (const double t : {end - 1e-3, end - 2e-12, end - 0.5e-12, end, end + 1e-3}) {
    auto st = db.prepare("SELECT reached_end(?1, ?2)");
    st.bind(1, t).bind(2, end);
    ASSERT_TRUE(st.step());
    EXPECT_EQ(st.integer(0) == 1, boycott::reached_end(t, end)) << "t = end " << t - end;
  }
  EXPECT_FALSE(boycott::reached_end(end - 2e-12, end));
  EXPECT_TRUE(boycott::reached_end(end - 0.5e-12, end));
  auto st = db.prepare("SELECT reached_end(NULL, 1) IS NULL");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.integer(0), 1);
}

TEST(StudyDatabase, Version1DatabaseMigratesToTheLatestKeepingItsRows) {
  TempDir d;
  const auto path = (d.path / "r.db").string();
  const auto study = bd::expand_study_string(kStudy);
  {
    bd::Database v1(path, bd::OpenMode::kCreate, 1);
    ASSERT_EQ(v1.version(), 1);
    EXPECT_FALSE(has_column(v1, "attempts", "run_dir"));
    bd::register_study(v1, study);
    // A version-1 attempt, written the way a version-1 program did (no run_dir column).
    v1.exec("INSERT INTO attempts(case_id, started_at, host, ranks, program_version) VALUES ('" +
            study.cases[0].id + "', '2026-01-01T00:00:00Z', 'h', 1, '0.0.1')");
  }
  bd::Database v2(path, bd::OpenMode::kExisting);
  EXPECT_EQ(v2.version(), bd::Database::latest_version());
  EXPECT_TRUE(has_column(v2, "attempts", "run_dir"));
  EXPECT_EQ(count(v2, "SELECT COUNT(*) FROM sqlite_master WHERE type='index' AND name='attempts_by_case'"),
            1);
  EXPECT_EQ(count(v2, "SELECT COUNT(*) FROM cases"), 4);
  EXPECT_EQ(count(v2, "SELECT COUNT(*) FROM attempts WHERE run_dir IS NULL"), 1);
}

// Schema 5 (results_schema/005_refinement.sql) on a database of schema 4 with a finished case: its
// rows kept, the table of added points there, a point recorded once however often it is offered.
TEST(StudyDatabase, Version4DatabaseMigratesAndRecordsEachRefinedPointOnce) {
  TempDir d;
  const auto path = (d.path / "r.db").string();
  auto study = bd::expand_study_string(std::string(kStudy) + R"(
[refine]
key = "gravity.angle_deg"
resolution = 2.5
)");
  {
    bd::Database v4(path, bd::OpenMode::kCreate, 4);
    ASSERT_EQ(v4.version(), 4);
    bd::register_study(v4, study);
    const auto attempt = bd::begin_attempt(v4, study.cases[0].id, 1, "/runs/x");
    bd::record_result(v4, attempt, study.cases[0].id,
                      {{"mean_settling_velocity_m_s", -0.1}, {"settling_velocity_stderr_m_s", 0.001}});
  }
  {
    bd::Database ro(path, bd::OpenMode::kReadOnly);
    EXPECT_FALSE(bd::has_refined_points(ro));
    EXPECT_TRUE(bd::refined_points(ro, "s").empty())
        << "a query reads an older database as one without points";
  }
  bd::Database db(path, bd::OpenMode::kExisting);
  EXPECT_EQ(db.version(), bd::Database::latest_version());
  EXPECT_TRUE(bd::has_refined_points(db));
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM cases"), 4);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 1);
  const auto curves = bd::refine_series(study);
  const bd::StudyCase c = bd::refined_case(study, curves[0], 67.5, 0);
  const bd::RefinedPoint p{"s", "a", "", 0, c.id, "gravity.angle_deg", 67.5, "the fit's vertex", ""};
  const auto first = bd::record_refined_point(db, p, c);
  EXPECT_FALSE(first.added_at.empty());
  // Another driver offering a point for the same round gets the recorded one; nothing is added.
  auto other = p;
  other.value = 70.0;
  other.case_id = bd::refined_case(study, curves[0], 70.0, 0).id;
  const auto second = bd::record_refined_point(db, other, bd::refined_case(study, curves[0], 70.0, 0));
  EXPECT_EQ(second.value, 67.5);
  EXPECT_EQ(second.case_id, c.id);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM refined_points"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases WHERE study = 's'"), 5);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM case_values WHERE case_id = '" + c.id + "'"), 1);
  const auto rows = bd::refined_points(db, "s");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].reason, "the fit's vertex");
}

TEST(StudyDatabase, NewerSchemaIsRefusedAndLeftUnchanged) {
  TempDir d;
  const auto path = (d.path / "r.db").string();
  {
    bd::Database db(path, bd::OpenMode::kCreate);
    db.exec("PRAGMA user_version = 99");
    db.exec("PRAGMA journal_mode = DELETE");
  }
  const auto before = file_bytes(path);
  try {
    bd::Database db(path, bd::OpenMode::kCreate);
    FAIL() << "a version-99 database was opened";
  } catch (const bd::DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("schema version 99"), std::string::npos) << e.what();
  }
  EXPECT_EQ(file_bytes(path), before);
}

TEST(StudyDatabase, AMissingColumnOrTableIsNamedNotReportedAsRawSql) {
  TempDir d;
  const auto path = (d.path / "r.db").string();
  {
    bd::Database db(path, bd::OpenMode::kCreate);
    db.exec("ALTER TABLE results DROP COLUMN mean_settling_velocity_m_s");  // changed by hand
  }
  bd::Database db(path, bd::OpenMode::kReadOnly);
  try {
    bd::query_curve(db, "any", "");
    FAIL() << "a results table without mean_settling_velocity_m_s was read";
  } catch (const bd::DatabaseError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("has no column 'mean_settling_velocity_m_s'"), std::string::npos) << what;
    EXPECT_NE(what.find("in table results"), std::string::npos) << what;
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_EQ(what.find("SELECT"), std::string::npos) << "no raw SQL: " << what;
  }
}

TEST(StudyDatabase, ConcurrentWritersFromSeveralProcessesLoseNothing) {
  TempDir d;
  const auto path = (d.path / "r.db").string();
  const auto study = bd::expand_study_string(kStudy);
  {
    bd::Database db(path, bd::OpenMode::kCreate);
    bd::register_study(db, study);
  }
  constexpr int kProcs = 4, kEach = 40;
  std::vector<pid_t> kids;
  for (int p = 0; p < kProcs; ++p) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int rc = 0;
      try {
        // Each process opens its own connection, as separate drivers would.
        bd::Database db(path, bd::OpenMode::kExisting);
        for (int i = 0; i < kEach; ++i) {
          const auto& c = study.cases[static_cast<std::size_t>(i) % study.cases.size()];
          const auto a = bd::begin_attempt(db, c.id + "", 1, "x");
          bd::finish_attempt(db, a, 75, "interrupted");
          bd::register_study(db, study);
        }
      } catch (const std::exception& e) {
        std::fprintf(stderr, "writer %d: %s\n", p, e.what());
        rc = 1;
      }
      _exit(rc);
    }
    kids.push_back(pid);
  }
  for (pid_t k : kids) {
    int st = 0;
    waitpid(k, &st, 0);
    EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  }
  bd::Database db(path, bd::OpenMode::kExisting);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), kProcs * kEach);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 75 AND ended_at IS NOT NULL"),
            kProcs * kEach);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases"), 4);
}

TEST(StudyDatabase, FailedTransactionLeavesNoTrace) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  bd::register_study(db, bd::expand_study_string(kStudy));
  EXPECT_THROW(db.transaction([&] {
    db.exec("DELETE FROM study_cases");
    throw std::runtime_error("stop");
  }),
               std::runtime_error);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases"), 4);
}

TEST(StudyDatabase, CurveRatioAndPropagatedErrorFollowTheRecordedResults) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(kStudy);
  bd::register_study(db, study);
  for (const auto& c : study.cases) {
    const double w = -0.01 * (c.params.gravity.angle_deg == 90.0 ? 1.0 : 1.5) * (c.group == "b" ? 0.5 : 1.0);
    const nlohmann::json summary = {{"scene", "inclined_settling"},
                                    {"case_id", c.id},
                                    {"status", "done"},
                                    {"mean_settling_velocity_m_s", w},
                                    {"settling_velocity_stderr_m_s", std::abs(w) * 0.02},
                                    {"simulated_time_s", 2.0},
                                    {"wall_time_s", 1.0},
                                    {"particle_steps", 1000},
                                    {"max_rel_error_vs_analytic", 0.01}};
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary);
  }
  const auto pts = bd::query_curve(db, "s");
  ASSERT_EQ(pts.size(), 4u);
  EXPECT_EQ(pts[0].group, "a");
  EXPECT_EQ(pts[0].angle_deg, 45.0);
  EXPECT_DOUBLE_EQ(pts[0].w_m_s, -0.015);
  EXPECT_DOUBLE_EQ(*pts[0].r_acc, 1.5);
  // |r| sqrt((s/w)^2 + (s90/w90)^2) with 2 % relative errors on both.
  EXPECT_NEAR(*pts[0].r_acc_err, 1.5 * std::sqrt(2.0) * 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(*pts[1].r_acc, 1.0);
  EXPECT_EQ(*pts[1].r_acc_err, 0.0);
  EXPECT_EQ(pts[2].group, "b");
  EXPECT_DOUBLE_EQ(pts[2].w_m_s, -0.0075);
  EXPECT_EQ(bd::query_curve(db, "s", "b").size(), 2u);
  EXPECT_EQ(
      count(db,
            "SELECT COUNT(*) FROM results WHERE validation_errors_json LIKE '%max_rel_error_vs_analytic%' "
            "AND average_from_s = 1.0 AND average_to_s = 2.0"),
      4);
}

// docs/results/*.csv carry, per point, the particle count and the window its <<w_p>> averages
// over (../shared/design.md, section 7): from the summary where it says (a window chosen by
// average_from = "auto", the simulated time reached), else from the case.
TEST(StudyDatabase, CurveRowsCarryTheParticleCountAndTheWindowOfTheirRuns) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(R"(
name = "win"
[base.time]
end = 2.0
average_from = 1.0
[matrix]
"gravity.angle_deg" = [45, 90]
)");
  bd::register_study(db, study);
  for (const auto& c : study.cases) {
    nlohmann::json summary = {
        {"scene", "inclined_settling"},
        {"case_id", c.id},
        {"status", "completed"},
        {"mean_settling_velocity_m_s", c.params.gravity.angle_deg == 90.0 ? -0.08 : -0.16},
        {"settling_velocity_stderr_m_s", 0.001},
        {"particle_count", 2398}};
    // 45 deg: a run that chose its own window and stopped at 1.75 s; 90 deg: the case's window.
    if (c.params.gravity.angle_deg == 45.0) {
      summary["average_from_s"] = 0.6;
      summary["simulated_time_s"] = 1.75;
    }
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary);
  }
  const auto pts = bd::query_curve(db, "win");
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(*pts[0].n_particles, 2398);
  EXPECT_DOUBLE_EQ(*pts[0].average_from_s, 0.6);
  EXPECT_DOUBLE_EQ(*pts[0].end_s, 1.75);
  EXPECT_DOUBLE_EQ(*pts[1].average_from_s, 1.0);
  EXPECT_DOUBLE_EQ(*pts[1].end_s, 2.0);
  const std::string csv = bd::format_curve(pts, bd::ListingFormat::kCsv);
  const std::string header = csv.substr(0, csv.find('\n'));
  for (const char* col : {"angle_deg", "mean_settling_velocity_m_s", "error_m_s", "n_particles",
                          "average_from_s", "end_s", "group"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos)
        << col << ": " << header;
  EXPECT_NE(csv.find(",2398,0.6,1.75,"), std::string::npos) << csv;
  const auto json = nlohmann::json::parse(bd::format_curve(pts, bd::ListingFormat::kJson));
  EXPECT_EQ(json[1]["n_particles"], 2398);
  EXPECT_DOUBLE_EQ(json[1]["end_s"].get<double>(), 2.0);
}

TEST(StudyDatabase, CurveAveragesReplicasAndPropagatesTheirScatterIntoRacc) {
  TempDir d;
  bd::Database db((d.path / "r.db").string(), bd::OpenMode::kCreate);
  const auto study = bd::expand_study_string(R"(
name = "rep"
replicas = 3
[base.time]
end = 2.0
average_from = 1.0
[matrix]
"gravity.angle_deg" = [45, 90]
)");
  bd::register_study(db, study);
  // Replica k: w = base (1 + 0.01 k (k - 1)); the within-run errors 1 % of |w|. The replicas at
  // 45 deg carry the new method, those at 90 deg none (a run that predates it: batch means).
  std::map<double, std::vector<double>> w_of;
  for (const auto& c : study.cases) {
    const double base = c.params.gravity.angle_deg == 90.0 ? -0.08 : -0.16;
    const double w = base * (1.0 + 0.01 * c.replica * (c.replica - 1));
    w_of[c.params.gravity.angle_deg].push_back(w);
    nlohmann::json summary = {{"scene", "inclined_settling"},
                              {"case_id", c.id},
                              {"status", "completed"},
                              {"mean_settling_velocity_m_s", w},
                              {"settling_velocity_stderr_m_s", 0.01 * std::abs(w)},
                              {"simulated_time_s", 2.0}};
    if (c.params.gravity.angle_deg == 45.0)
      summary["settling_velocity_error_method"] = "sokal_autocorrelation";
    bd::record_result(db, bd::begin_attempt(db, c.id, 1, "x"), c.id, summary);
  }
  const auto pts = bd::query_curve(db, "rep");
  ASSERT_EQ(pts.size(), 2u);
  auto stats = [](const std::vector<double>& w) {
    double m = 0.0, ss = 0.0;
    for (double x : w) m += x / w.size();
    for (double x : w) ss += (x - m) * (x - m);
    return std::pair{m, std::sqrt(ss / (w.size() - 1.0)) / std::sqrt(double(w.size()))};
  };
  const auto [m45, e45] = stats(w_of[45.0]);
  const auto [m90, e90] = stats(w_of[90.0]);
  EXPECT_EQ(pts[0].n_replicas, 3);
  EXPECT_EQ(pts[0].replica_case_ids.size(), 3u);
  EXPECT_NEAR(pts[0].w_m_s, m45, 1e-15);
  EXPECT_NEAR(*pts[0].between_replica_stderr_m_s, e45, 1e-15);
  EXPECT_NEAR(*pts[0].w_err_m_s, e45, 1e-15);
  double within = 0.0;
  for (double x : w_of[45.0]) within += 0.01 * std::abs(x) / 3.0;
  EXPECT_NEAR(*pts[0].mean_within_run_stderr_m_s, within, 1e-15);
  EXPECT_EQ(pts[0].error_method, "sokal_autocorrelation");
  EXPECT_EQ(pts[1].error_method, "batch_means");
  EXPECT_NEAR(*pts[0].r_acc, m45 / m90, 1e-12);
  // The covering errors: t at 2 degrees of freedom (the replicas' own errors of 1 % agree with
  // their scatter: no chi-square note), and r_acc's at Welch's (1947) degrees of freedom, written
  // out: each part's s^4 over its dof + 2, less 2, and at least the smaller part's dof (2).
  EXPECT_NEAR(*pts[0].error.error_m_s, boycott::stats::one_sigma_t_factor(2.0) * e45, 1e-15);
  const double a = e45 / m90, b = m45 / m90 * e90 / m90;
  const double nu =
      std::max(2.0, (a * a + b * b) * (a * a + b * b) / (a * a * a * a / 4.0 + b * b * b * b / 4.0) - 2.0);
  EXPECT_NEAR(*pts[0].r_acc_err, std::hypot(a, b) * boycott::stats::one_sigma_t_factor(nu), 1e-12);
  EXPECT_EQ(*pts[1].r_acc_err, 0.0);
  // The error keys of <<w_p>> are not validation errors.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results WHERE validation_errors_json LIKE '%settling_velocity%'"),
            0);
}
