// The driver against faults and against the real solver (issue 26): storage errors (exit 74) are
// retried after a back-off, never counted nor set aside, and stop the study after five in a row;
// the test double writes the real solver's summary keys and statuses; a summary the real solver
// finished but no driver recorded is recorded without rerunning; queries open the database
// read-only, refuse another program's SQLite file untouched and an empty --db, and print "n/a"
// for an error that was never recorded.
#include <signal.h>
#include <sqlite3.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "driver/store/database.hpp"
#include "study_process.hpp"

namespace bd = boycott::driver;
namespace fs = std::filesystem;

namespace {

const std::string kFake = std::string("python3 ") + FAKE_SOLVER;

using study_process::count;
using study_process::read;
using study_process::Run;
using study_process::run;
using study_process::spawn;
using study_process::TempDir;
using study_process::wait_run;
using study_process::write;

std::vector<std::string> study_run(const fs::path& study, const fs::path& db,
                                   const std::string& solver = kFake) {
  std::vector<std::string> a = {"study", "run", study.string(), "--db", db.string(), "--jobs", "1"};
  if (!solver.empty()) a.insert(a.end(), {"--solver-command", solver});
  return a;
}

bool any_set_aside(const fs::path& db) {
  for (const auto& e : fs::directory_iterator(db.string() + ".runs"))
    if (e.path().filename().string().find(".bad-") != std::string::npos) return true;
  return false;
}

// One case for the fake solver (8 steps).
const char* kOneCase = R"(
name = "one"
[base]
scene = "inclined_settling"
[base.particles]
count = 1000
[base.time]
end = 0.8
average_from = 0.4
[matrix]
"gravity.angle_deg" = [60]
)";

// Two angles for the fake solver (a curve with r_acc).
const char* kTwo = R"(
name = "small"
[base]
scene = "inclined_settling"
[base.particles]
count = 1000
[base.time]
end = 0.3
average_from = 0.1
[matrix]
"gravity.angle_deg" = [60, 90]
)";

// A real coupled case as small as the smoke test, a few steps.
const char* kRealCoupled = R"(
name = "real"
[base]
scene = "inclined_settling"
[base.particles]
volume_fraction = 0.113
[base.domain]
length_x = 0.02
width_y = 0.006
height_z = 0.02
cells = [20, 6, 20]
[base.time]
end = 0.01
average_from = 0.005
[matrix]
"gravity.angle_deg" = [60]
)";

}  // namespace

TEST(StudyRunStorage, ExitSeventyFourIsRetriedAfterABackOffNeitherCountedNorSetAside) {
  TempDir d;
  write(d.path / "s.toml", kOneCase);
  const auto db = d.path / "s.db";
  auto args = study_run(d.path / "s.toml", db);
  args.insert(args.end(), {"--retries", "0"});
  // Four storage errors in a row (one fewer than stops a study), then room again.
  const auto r = run(args, d.path, {{"FAKE_STORAGE_FAILS", "4"}, {"BOYCOTT_TEST_STORAGE_BACKOFF_S", "0.05"}});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 74"), 4);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE error_text LIKE '%No space left on device%'"), 4);
  EXPECT_FALSE(any_set_aside(db));
  EXPECT_NE(r.err.find("not counted as a failure"), std::string::npos) << r.err;
  // 0.05, 0.1, 0.2, 0.4 s: the back-off doubles.
  for (const char* wait :
       {"runs again in 0.05 s", "runs again in 0.1 s", "runs again in 0.2 s", "runs again in 0.4 s"})
    EXPECT_NE(r.err.find(wait), std::string::npos) << r.err;
  const auto status =
      run({"study", "status", (d.path / "s.toml").string(), "--db", db.string(), "--retries", "0"}, d.path);
  EXPECT_NE(status.out.find("1 case: 1 done, 0 running, 0 failed"), std::string::npos) << status.out;
}

TEST(StudyRunStorage, FiveStorageErrorsInARowStopTheStudyNamingTheCause) {
  TempDir d;
  write(d.path / "s.toml", kOneCase);
  const auto db = d.path / "s.db";
  const auto r = run(study_run(d.path / "s.toml", db), d.path,
                     {{"FAKE_STORAGE_FAILS", "always"}, {"BOYCOTT_TEST_STORAGE_BACKOFF_S", "0.02"}});
  EXPECT_EQ(r.rc, boycott::kExitStorageError) << r.err;
  EXPECT_NE(r.err.find("5 storage errors in a row"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 74"), 5);
  EXPECT_FALSE(any_set_aside(db));
  // The case is not failed: the next run (with room) finishes it.
  const auto status = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  EXPECT_NE(status.out.find("0 failed"), std::string::npos) << status.out;
  const auto again = run(study_run(d.path / "s.toml", db), d.path);
  EXPECT_EQ(again.rc, 0) << again.err;
}

TEST(FakeSolverContract, SummaryKeysAndStatusesMatchTheRealSolver) {
  TempDir d;
  write(d.path / "s.toml", kRealCoupled);
  const auto db = d.path / "s.db";
  // The real solver (this program) through the driver: a full case.json and a real summary.
  const auto r = run(study_run(d.path / "s.toml", db, ""), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  fs::path real_dir;
  for (const auto& e : fs::directory_iterator(db.string() + ".runs")) real_dir = e.path();
  const auto real = nlohmann::json::parse(read(real_dir / "summary.json"));
  const fs::path case_file = real_dir / "case.json";

  // The fake on the same case, made to take a few of its 0.1 s steps.
  auto the_case = nlohmann::json::parse(read(case_file));
  ASSERT_TRUE(the_case["time"].contains("end")) << the_case.dump();
  the_case["time"]["end"] = 0.5;
  const fs::path fake_case = d.path / "fake_case.json";
  write(fake_case, the_case.dump(2));
  const fs::path fake_dir = d.path / "fake" / real_dir.filename();
  fs::create_directories(fake_dir.parent_path());
  const auto f = wait_run(spawn({FAKE_SOLVER, "case", "run", fake_case.string(), "--out", fake_dir.string()},
                                d.path, {{"FAKE_STEP_WALL_S", "0"}}, "python3"),
                          d.path);
  ASSERT_EQ(f.rc, 0) << f.err;
  const auto fake = nlohmann::json::parse(read(fake_dir / "summary.json"));

  // Errors are n/a (null) when the averaging window holds fewer than 5 correlation times.
  const std::set<std::string> kNullable = {"settling_velocity_stderr_m_s", "settling_velocity_rel_stderr"};
  std::set<std::string> missing;
  for (const auto& [k, v] : fake.items()) {
    if (!real.contains(k)) {
      missing.insert(k);
    } else if (!(kNullable.count(k) && (real[k].is_null() || v.is_null()))) {
      EXPECT_EQ(real[k].type_name(), std::string(v.type_name())) << k;
    }
  }
  EXPECT_TRUE(missing.empty()) << "keys the test double writes and the real solver does not: "
                               << nlohmann::json(missing).dump();
  for (const char* k :
       {"scene", "case_id", "status", "mean_settling_velocity_m_s", "settling_velocity_stderr_m_s",
        "simulated_time_s", "wall_time_s", "particle_steps"}) {
    EXPECT_TRUE(real.contains(k)) << k;
    EXPECT_TRUE(fake.contains(k)) << k;
  }
  EXPECT_EQ(real["status"], std::string(boycott::kStatusCompleted));
  EXPECT_EQ(fake["status"], real["status"]);
  EXPECT_TRUE(boycott::is_finished_status(real["status"].get<std::string>()));

  // Stopped by SIGTERM: both exit 75 with the summary marked interrupted.
  const auto stopped = [&](const std::vector<std::string>& args, const std::string& program,
                           const fs::path& out, const fs::path& sign) {
    const pid_t pid = spawn(args, d.path, {{"FAKE_STEP_WALL_S", "0.2"}}, program);
    for (int i = 0; i < 1000 && !fs::exists(sign); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(pid, SIGTERM);
    const auto res = wait_run(pid, d.path);
    EXPECT_EQ(res.rc, boycott::kExitInterrupted) << res.err;
    return nlohmann::json::parse(read(out / "summary.json"));
  };
  const fs::path real_stop = d.path / "real_stop", fake_stop = d.path / "fake_stop" / real_dir.filename();
  const auto rs = stopped({"case", "run", case_file.string(), "--out", real_stop.string(), "--quiet", "--set",
                           "time.end=5", "--set", "time.checkpoint_every=0.005"},
                          BOYCOTT_BIN, real_stop, real_stop / "checkpoints");
  const auto fs_ = stopped({FAKE_SOLVER, "case", "run", fake_case.string(), "--out", fake_stop.string()},
                           "python3", fake_stop, fake_stop / "checkpoint.json");
  EXPECT_EQ(rs["status"], std::string(boycott::kStatusInterrupted));
  EXPECT_EQ(fs_["status"], rs["status"]);
}

TEST(StudyRunLeftSummary, RealSolverSummaryIsRecordedWithoutRerunning) {
  TempDir d;
  write(d.path / "s.toml", kRealCoupled);
  const auto first = d.path / "first.db";
  ASSERT_EQ(run(study_run(d.path / "s.toml", first, ""), d.path).rc, 0);
  fs::path left;
  for (const auto& e : fs::directory_iterator(first.string() + ".runs")) left = e.path();
  // The state a driver killed between the solver's end and the recording leaves: a run folder
  // with the real solver's summary.json and no result in the database.
  const auto db = d.path / "s.db";
  const fs::path dir = fs::path(db.string() + ".runs") / left.filename();
  fs::create_directories(dir.parent_path());
  fs::copy(left, dir, fs::copy_options::recursive);
  const auto log_before = fs::file_size(dir / "solver.log");
  // A solver that would fail if it ran.
  const auto r = run(study_run(d.path / "s.toml", db, "/bin/false"), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 0"), 1);
  EXPECT_EQ(fs::file_size(dir / "solver.log"), log_before) << "the solver ran again";
  const auto summary = nlohmann::json::parse(read(dir / "summary.json"));
  bd::Database c(db.string(), bd::OpenMode::kReadOnly);
  auto st = c.prepare("SELECT mean_settling_velocity_m_s FROM results");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.real(0), summary["mean_settling_velocity_m_s"].get<double>());
}

namespace {

/// A study database of two finished fake cases at d/s.db.
fs::path fake_study_db(const TempDir& d) {
  write(d.path / "s.toml", kTwo);
  const auto db = d.path / "s.db";
  EXPECT_EQ(run(study_run(d.path / "s.toml", db), d.path).rc, 0);
  return db;
}

/// fake_study_db, then the study file's time.end raised from 0.3 to 0.6 s (nothing run since).
fs::path fake_study_db_end_raised(const TempDir& d) {
  const auto db = fake_study_db(d);
  auto study = std::string(kTwo);
  study.replace(study.find("end = 0.3"), 9, "end = 0.6");
  write(d.path / "s.toml", study);
  return db;
}

}  // namespace

// A finished run whose case's time.end has since been raised (time.end is not part of the id) is
// continued by `study run`, not recorded by `study collect`: `study status` must not send the user
// to collect it.
TEST(StudyStatus, ARunFinishedAtAnEndSinceRaisedIsNotListedAsUncollected) {
  TempDir d;
  const auto db = fake_study_db_end_raised(d);
  // `study collect` registers the raised end and records nothing.
  const auto c = run({"study", "collect", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  ASSERT_EQ(c.rc, 0) << c.err;
  const auto r = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("2 cases: 0 done"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("not recorded yet"), std::string::npos) << r.out;
}

// The database holds each case's parameters as of the last `study run`; `study status` and
// `study plan` read the file as it is now: a time.end raised since shows the finished cases as
// pending (the plan prices the rest), before any run or collect registers the new end.
TEST(StudyStatus, AnEndRaisedInTheFileShowsItsFinishedCasesPendingBeforeAnyRun) {
  TempDir d;
  const auto db = fake_study_db_end_raised(d);
  const auto r = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("2 cases: 0 done"), std::string::npos) << r.out;
  const auto p =
      run({"study", "plan", (d.path / "s.toml").string(), "--db", db.string(), "--format", "csv"}, d.path);
  ASSERT_EQ(p.rc, 0) << p.err;
  EXPECT_EQ(p.out.find(",done,"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find(",pending,"), std::string::npos) << p.out;
  // Neither command wrote the new end: the stored parameters still end at 0.3 s.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM cases WHERE json_extract(params_json, '$.time.end') = 0.3"), 2);
}

// `study run --stop-after S`: after S wall seconds every running case checkpoints and stops as on
// a SIGTERM to the driver (exit 75, the case interrupted, not failed), and the same command
// resumes it. The fake's 1 000 steps of 0.05 s of wall time each cannot finish in the 1 s given,
// on any machine: nothing here depends on how fast it runs.
TEST(StudyRun, StopAfterCheckpointsTheRunningCasesAndTheSameCommandResumes) {
  TempDir d;
  std::string study = kOneCase;
  study.replace(study.find("end = 0.8"), 9, "end = 100.0");
  write(d.path / "s.toml", study);
  const auto db = d.path / "s.db";
  auto args = study_run(d.path / "s.toml", db);
  args.insert(args.end(), {"--stop-after", "1"});
  const std::map<std::string, std::string> env{{"FAKE_STEP_WALL_S", "0.05"}};
  for (int attempt = 1; attempt <= 2; ++attempt) {
    const auto r = run(args, d.path, env);
    EXPECT_EQ(r.rc, 75) << r.out << r.err;
    EXPECT_NE(r.out.find("stopped after --stop-after 1 s: 0 of 1 case done; run the same command to resume"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 75"), attempt);
    EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status <> 75"), 0);
  }
  const auto st = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  EXPECT_NE(st.out.find("0 failed, 1 interrupted"), std::string::npos) << st.out;
  const auto bad =
      run({"study", "run", (d.path / "s.toml").string(), "--db", db.string(), "--stop-after", "0"}, d.path);
  EXPECT_EQ(bad.rc, 2) << bad.err;
}

// Two angles bracket no peak: `query peak` shows the higher point, says why, and gives its angle
// no interval (a zero-width one would read as a peak known exactly).
TEST(Queries, APeakOfTwoPointsIsNotEstimatedAndSaysSo) {
  TempDir d;
  const auto db = fake_study_db(d);
  const auto q = run({"query", "peak", "--db", db.string(), "--study", "small", "--format", "json"}, d.path);
  ASSERT_EQ(q.rc, 0) << q.err;
  const auto rows = nlohmann::json::parse(q.out);
  ASSERT_EQ(rows.size(), 1u) << q.out;
  EXPECT_EQ(rows[0]["n_points"], 2);
  EXPECT_EQ(rows[0]["status"], "too_few_points");
  EXPECT_EQ(rows[0]["resolved"], false);
  for (const char* key : {"angle_err_deg", "angle_low_deg", "angle_high_deg"})
    EXPECT_TRUE(rows[0][key].is_null()) << key << ": " << q.out;
  const double angle = rows[0]["angle_deg"].get<double>();
  EXPECT_TRUE(angle == 60.0 || angle == 90.0) << q.out;
  const auto t = run({"query", "peak", "--db", db.string(), "--study", "small"}, d.path);
  ASSERT_EQ(t.rc, 0) << t.err;
  EXPECT_NE(t.out.find("(highest point)"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("2 points: a peak needs 3 to be bracketed"), std::string::npos) << t.out;
  const auto c = run({"query", "peak", "--db", db.string(), "--study", "small", "--format", "csv"}, d.path);
  ASSERT_EQ(c.rc, 0) << c.err;
  EXPECT_EQ(c.out.find("nan"), std::string::npos) << c.out;
}

// `study plan` prices [refine]'s points only on curves that can bracket a peak: a group of two
// angles gets none (the refinement stops at too_few_points), one of three its max_points.
TEST(StudyPlan, RefinesBudgetLeavesOutCurvesOfTooFewPointsToBracketAPeak) {
  TempDir d;
  write(d.path / "s.toml", std::string(kTwo).replace(std::string(kTwo).find("[matrix]"), std::string::npos,
                                                     R"([[group]]
name = "three"
zip = { "gravity.angle_deg" = [30, 60, 90] }
[[group]]
name = "two"
set = { "fluid.viscosity" = 2.0e-3 }
zip = { "gravity.angle_deg" = [60, 90] }
[refine]
key = "gravity.angle_deg"
resolution = 5.0
max_points = 2
)"));
  const auto r = run(
      {"study", "plan", (d.path / "s.toml").string(), "--db", (d.path / "s.db").string(), "--format", "json"},
      d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto curves = nlohmann::json::parse(r.out)["refinement"]["curves"];
  ASSERT_EQ(curves.size(), 2u) << r.out;
  EXPECT_EQ(curves[0]["group"], "three");
  EXPECT_EQ(curves[0]["max_cases"], 2);
  EXPECT_EQ(curves[1]["group"], "two");
  EXPECT_EQ(curves[1]["max_cases"], 0);
  EXPECT_EQ(curves[1]["max_core_s"], 0.0);
}

TEST(Queries, ReadOnlyDatabaseIsQueriedWithoutWritingToIt) {
  TempDir d;
  const auto db = fake_study_db(d);
  const fs::path mnt = d.path / "ro";
  fs::create_directories(mnt);
  bool mounted = ::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=4m") == 0;
  if (!mounted && geteuid() == 0) GTEST_SKIP() << "cannot mount a tmpfs (" << std::strerror(errno) << ")";
  fs::copy_file(db, mnt / "s.db");
  const auto bytes = read(mnt / "s.db");
  if (mounted) {
    ASSERT_EQ(::mount("tmpfs", mnt.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, nullptr), 0)
        << std::strerror(errno);
  } else {
    fs::permissions(mnt / "s.db", fs::perms::owner_read);
    fs::permissions(mnt, fs::perms::owner_read | fs::perms::owner_exec);
  }
  const std::string ro = (mnt / "s.db").string();
  const auto curve = run({"query", "curve", "--db", ro, "--study", "small"}, d.path);
  EXPECT_EQ(curve.rc, 0) << curve.err;
  EXPECT_NE(curve.out.find("r_acc"), std::string::npos) << curve.out;
  for (const std::vector<std::string>& q :
       std::vector<std::vector<std::string>>{{"query", "cases", "--db", ro},
                                             {"query", "validation", "--db", ro},
                                             {"study", "status", (d.path / "s.toml").string(), "--db", ro}}) {
    const auto r = run(q, d.path);
    EXPECT_EQ(r.rc, 0) << q[1] << ": " << r.err;
  }
  EXPECT_EQ(read(mnt / "s.db"), bytes);
  if (mounted) {
    ::umount(mnt.c_str());
  } else {
    fs::permissions(mnt, fs::perms::owner_all);
  }
}

TEST(Queries, ReadOnlyCommandsLeaveNoWalOrShmFilesBehind) {
  // A finished study's database (WAL mode, its writer gone: no -wal, no -shm): every read-only
  // command leaves it so, and the data it reads are the same. A query cannot write through its
  // handle either.
  TempDir d;
  const auto db = fake_study_db(d);
  auto beside = [&] { return fs::exists(db.string() + "-wal") || fs::exists(db.string() + "-shm"); };
  ASSERT_FALSE(beside());
  for (const std::vector<std::string>& q : std::vector<std::vector<std::string>>{
           {"query", "curve", "--db", db.string(), "--study", "small"},
           {"query", "cases", "--db", db.string()},
           {"study", "status", (d.path / "s.toml").string(), "--db", db.string()},
           {"study", "plan", (d.path / "s.toml").string(), "--db", db.string()}}) {
    const auto r = run(q, d.path);
    EXPECT_EQ(r.rc, 0) << q[0] << " " << q[1] << ": " << r.err;
    EXPECT_FALSE(beside()) << q[0] << " " << q[1] << " left a -wal or -shm file";
  }
  bd::Database c(db.string(), bd::OpenMode::kReadOnly);
  EXPECT_THROW(c.exec("DELETE FROM results"), std::exception);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 2);
}

TEST(Queries, QueryLeavesARollbackJournalDatabaseAsItWas) {
  TempDir d;
  const auto db = fake_study_db(d);
  {
    bd::Database c(db.string(), bd::OpenMode::kExisting);
    c.exec("PRAGMA journal_mode = DELETE");
  }
  const auto bytes = read(db);
  const auto r = run({"query", "curve", "--db", db.string(), "--study", "small"}, d.path);
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(read(db), bytes) << "no WAL switch, no write";
  EXPECT_FALSE(fs::exists(db.string() + "-wal"));
}

TEST(Queries, ForeignSqliteFileIsRefusedUntouched) {
  TempDir d;
  write(d.path / "s.toml", kTwo);
  const fs::path f = d.path / "other.sqlite";
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(f.c_str(), &h), SQLITE_OK);
  sqlite3_exec(
      h, "CREATE TABLE photos(id INTEGER PRIMARY KEY, name TEXT); INSERT INTO photos(name) VALUES ('a');",
      nullptr, nullptr, nullptr);
  sqlite3_close(h);
  const auto bytes = read(f);
  for (const std::vector<std::string>& q : std::vector<std::vector<std::string>>{
           {"query", "curve", "--db", f.string(), "--study", "small"},
           {"query", "cases", "--db", f.string()},
           {"query", "validation", "--db", f.string()},
           {"query", "work-precision", "--db", f.string(), "--study", "small"},
           {"study", "status", (d.path / "s.toml").string(), "--db", f.string()},
           study_run(d.path / "s.toml", f)}) {
    const auto r = run(q, d.path);
    EXPECT_EQ(r.rc, boycott::kExitInputError) << q[1] << ": " << r.err;
    EXPECT_NE(r.err.find("another program"), std::string::npos) << q[1] << ": " << r.err;
    EXPECT_EQ(read(f), bytes) << q[1];
    EXPECT_FALSE(fs::exists(f.string() + "-wal")) << q[1];
    EXPECT_FALSE(fs::exists(f.string() + "-shm")) << q[1];
  }
}

TEST(Queries, EmptyDbOptionIsRefusedAsUsage) {
  TempDir d;
  write(d.path / "s.toml", kTwo);
  for (const std::vector<std::string>& q :
       std::vector<std::vector<std::string>>{{"query", "curve", "--db", "", "--study", "small"},
                                             {"query", "cases", "--db", ""},
                                             {"study", "status", (d.path / "s.toml").string(), "--db", ""},
                                             {"study", "run", (d.path / "s.toml").string(), "--db", ""}}) {
    const auto r = run(q, d.path);
    EXPECT_EQ(r.rc, boycott::kExitInputError) << q[1] << ": " << r.err;
    EXPECT_NE(r.err.find("--db"), std::string::npos) << r.err;
  }
}

TEST(Queries, MissingErrorPrintsNotAvailable) {
  TempDir d;
  const auto db = fake_study_db(d);
  {
    bd::Database c(db.string(), bd::OpenMode::kExisting);
    c.exec("UPDATE results SET settling_velocity_stderr_m_s = NULL");
  }
  const auto table = run({"query", "curve", "--db", db.string(), "--study", "small"}, d.path);
  ASSERT_EQ(table.rc, 0) << table.err;
  EXPECT_NE(table.out.find("+- n/a"), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("+- 0.0000"), std::string::npos) << table.out;
  const auto json =
      run({"query", "curve", "--db", db.string(), "--study", "small", "--format", "json"}, d.path);
  for (const auto& p : nlohmann::json::parse(json.out)) {
    EXPECT_TRUE(p["stderr_m_s"].is_null()) << p.dump();
    if (p["angle_deg"] != 90.0) {
      EXPECT_TRUE(p["r_acc_err"].is_null()) << p.dump();
    }
  }
}
