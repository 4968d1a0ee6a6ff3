#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "driver/store/database.hpp"
#include "study_process.hpp"

namespace bd = boycott::driver;
namespace fs = std::filesystem;

namespace {

using namespace study_process;

// Every fake case is 8 steps of FAKE_STEP_WALL_S.
const std::string kSmallBase = R"(
[base]
scene = "inclined_settling"
seed = 1
[base.particles]
count = 1000
[base.time]
end = 0.8
average_from = 0.4
)";
// 2 groups x 3 angles.
const std::string kStudy = "name = \"small\"\n" + kSmallBase + R"(
[[group]]
name = "base"
[[group]]
name = "Ga"
set = { "fluid.viscosity" = 1.0e-2 }
[matrix]
"gravity.angle_deg" = [30, 60, 90]
)";

/// Waits until some case of the study at db has written a checkpoint (so a stop lands mid-case).
void wait_for_checkpoint(const fs::path& db) {
  const fs::path runs = db.string() + ".runs";
  for (int i = 0; i < 1000; ++i) {
    std::error_code ec;
    if (fs::exists(runs, ec))
      for (const auto& e : fs::directory_iterator(runs, ec))
        if (fs::exists(e.path() / "checkpoint.json", ec)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

/// case id -> (mean, stderr, particle_steps) as recorded.
std::map<std::string, std::tuple<double, double, std::int64_t>> results(const fs::path& db) {
  bd::Database d(db.string(), bd::OpenMode::kExisting);
  auto st = d.prepare(
      "SELECT case_id, mean_settling_velocity_m_s, settling_velocity_stderr_m_s, particle_steps "
      "FROM results");
  std::map<std::string, std::tuple<double, double, std::int64_t>> out;
  while (st.step()) out[st.text(0)] = {st.real(1), st.real(2), st.integer(3)};
  return out;
}

}  // namespace

TEST(StudyRun, RunsEveryCaseOnceAndQueryCurveMatchesTheCaseSummaries) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  const auto r = run(study_run(d.path / "s.toml", db, 3), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("6 of 6 cases done"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("r_acc"), std::string::npos) << "the curve is printed at the end";
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 6);
  // --jobs 3: some attempts overlapped in time.
  EXPECT_GE(count(db,
                  "SELECT MAX((SELECT COUNT(*) FROM attempts b WHERE b.started_at <= a.started_at AND "
                  "b.ended_at > a.started_at)) FROM attempts a"),
            2);

  const auto q = run({"query", "curve", "--db", db.string(), "--study", "small", "--format", "json", "--plot",
                      (d.path / "c.svg").string()},
                     d.path);
  ASSERT_EQ(q.rc, 0) << q.err;
  const auto curve = nlohmann::json::parse(q.out);
  ASSERT_EQ(curve.size(), 6u);
  std::map<std::string, double> w90;
  for (const auto& p : curve) {
    const auto summary = nlohmann::json::parse(
        read(fs::path(db.string() + ".runs") / p["case_id"].get<std::string>() / "summary.json"));
    EXPECT_DOUBLE_EQ(p["mean_settling_velocity_m_s"].get<double>(),
                     summary["mean_settling_velocity_m_s"].get<double>());
    EXPECT_DOUBLE_EQ(p["stderr_m_s"].get<double>(), summary["settling_velocity_stderr_m_s"].get<double>());
    if (p["angle_deg"] == 90.0) w90[p["group"]] = summary["mean_settling_velocity_m_s"].get<double>();
  }
  for (const auto& p : curve)
    EXPECT_NEAR(p["r_acc"].get<double>(), p["mean_settling_velocity_m_s"].get<double>() / w90[p["group"]],
                1e-12);
  // The plot as SVG (drawn by Cairo: strokes and glyphs as paths), of the curve's size.
  const auto svg = read(d.path / "c.svg");
  const auto root = svg.find("<svg");
  ASSERT_NE(root, std::string::npos) << svg.substr(0, 200);
  const auto head = svg.substr(root, svg.find('>', root) - root);
  EXPECT_NE(head.find("width=\"1000px\""), std::string::npos) << head;
  EXPECT_NE(head.find("height=\"470px\""), std::string::npos) << head;
  EXPECT_NE(svg.rfind("</svg>"), std::string::npos);
  std::size_t paths = 0;
  for (auto pos = svg.find("<path"); pos != std::string::npos; pos = svg.find("<path", pos + 1)) ++paths;
  EXPECT_GT(paths, 20u);
  // --plot FILE.pdf: the same drawing as PDF.
  const auto qpdf = run({"query", "curve", "--db", db.string(), "--study", "small", "--plot",
                         (d.path / "c.pdf").string(), "--overlay-paper"},
                        d.path);
  ASSERT_EQ(qpdf.rc, 0) << qpdf.err;
  const auto pdf = read(d.path / "c.pdf");
  EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u);
  EXPECT_GT(pdf.size(), 2000u);
  EXPECT_NE(pdf.find("%%EOF"), std::string::npos);

  // A second run has nothing to do.
  const auto again = run(study_run(d.path / "s.toml", db), d.path);
  EXPECT_EQ(again.rc, 0);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 6);
  const auto csv =
      run({"query", "curve", "--db", db.string(), "--study", "small", "--group", "Ga", "--format", "csv"},
          d.path);
  EXPECT_EQ(std::count(csv.out.begin(), csv.out.end(), '\n'), 4);
  const auto status = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  EXPECT_NE(status.out.find("6 cases: 6 done"), std::string::npos) << status.out;
}

TEST(StudyRun, KillNineAtRandomMomentsThenRerunEndsWithTheUninterruptedResults) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto ref_db = d.path / "ref.db";
  ASSERT_EQ(run(study_run(d.path / "s.toml", ref_db), d.path).rc, 0);
  const auto reference = results(ref_db);
  ASSERT_EQ(reference.size(), 6u);

  const auto db = d.path / "s.db";
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_ms(30, 600);
  // The commit delay widens the moment of the result transaction so that some kills land in it.
  const std::map<std::string, std::string> env = {{"FAKE_STEP_WALL_S", "0.02"},
                                                  {"BOYCOTT_TEST_COMMIT_DELAY_S", "0.05"}};
  for (int k = 0; k < 6; ++k) {
    const pid_t pid = spawn(study_run(d.path / "s.toml", db), d.path, env);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    ::kill(pid, SIGKILL);
    wait_run(pid, d.path);
  }
  // The orphaned solvers got SIGTERM from the kernel (parent death) and stop at a checkpoint;
  // once they are gone nothing holds the run folders and status must not claim "running". How
  // soon they are gone depends on the machine's load: status is asked until it says so (a status
  // that never does fails after ~1 min of asking).
  const std::vector<std::string> ask = {"study", "status", (d.path / "s.toml").string(), "--db", db.string()};
  auto status = run(ask, d.path);
  for (int i = 0; i < 300 && status.out.find(" 0 running") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    status = run(ask, d.path);
  }
  EXPECT_NE(status.out.find(" 0 running"), std::string::npos) << status.out;
  // The plan reads the states the same way.
  const auto plan =
      run({"study", "plan", (d.path / "s.toml").string(), "--db", db.string(), "--format", "csv"}, d.path);
  ASSERT_EQ(plan.rc, 0) << plan.err;
  EXPECT_EQ(plan.out.find(",running,"), std::string::npos) << plan.out;
  const auto r = run(study_run(d.path / "s.toml", db), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE ended_at IS NULL"), 0);
  EXPECT_GE(count(db, "SELECT COUNT(*) FROM attempts WHERE error_text LIKE 'abandoned%'"), 1)
      << "some kill landed while a case was running";
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status NOT IN (0, 75, 130, 143)"), 0)
      << "no interruption may count as a failure";
  const auto got = results(db);
  ASSERT_EQ(got.size(), reference.size());
  for (const auto& [id, v] : reference) {
    ASSERT_TRUE(got.count(id)) << id;
    EXPECT_DOUBLE_EQ(std::get<0>(got.at(id)), std::get<0>(v)) << id;
    EXPECT_DOUBLE_EQ(std::get<1>(got.at(id)), std::get<1>(v)) << id;
    EXPECT_EQ(std::get<2>(got.at(id)), std::get<2>(v)) << id;
  }
}

TEST(StudyRun, SigintStopsCasesAtACheckpointAndRerunResumesThem) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  const pid_t pid = spawn(study_run(d.path / "s.toml", db), d.path, {{"FAKE_STEP_WALL_S", "0.1"}});
  wait_for_checkpoint(db);
  ::kill(pid, SIGINT);
  const auto stopped = wait_run(pid, d.path);
  EXPECT_EQ(stopped.rc, 75) << stopped.err;
  EXPECT_NE(stopped.out.find("run the same command to resume"), std::string::npos);
  EXPECT_GE(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 75"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE ended_at IS NULL"), 0);
  // The interrupted case that had checkpointed left its checkpoint part-way. With two jobs the
  // other case may have been stopped before its first step, with no checkpoint yet: that one
  // has nothing to check.
  bd::Database d75(db.string(), bd::OpenMode::kExisting);
  auto st = d75.prepare("SELECT run_dir FROM attempts WHERE exit_status = 75");
  int checkpointed = 0;
  while (st.step()) {
    const fs::path ckpt_file = fs::path(st.text(0)) / "checkpoint.json";
    if (!fs::exists(ckpt_file)) continue;
    ++checkpointed;
    const auto ckpt = nlohmann::json::parse(read(ckpt_file));
    EXPECT_GT(ckpt["step"].get<int>(), 0);
    EXPECT_LT(ckpt["step"].get<int>(), 8);
  }
  EXPECT_GE(checkpointed, 1);
  // The last progress line counts every case not done as pending, the stopped ones too.
  const auto done = count(db, "SELECT COUNT(*) FROM results");
  const auto last_line = stopped.err.rfind("study small:");
  ASSERT_NE(last_line, std::string::npos) << stopped.err;
  EXPECT_NE(stopped.err.find(
                std::to_string(done) + " done, 0 running, 0 failed, " + std::to_string(6 - done) + " pending",
                last_line),
            std::string::npos)
      << stopped.err.substr(last_line);

  const auto r = run(study_run(d.path / "s.toml", db), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
}

TEST(StudyRun, CasesStoppedPartWayResumeBeforeAnyCaseStartsAfresh) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  // One job: the study's first case runs alone and is stopped after its first checkpoint.
  const pid_t pid = spawn(study_run(d.path / "s.toml", db, 1), d.path, {{"FAKE_STEP_WALL_S", "0.1"}});
  wait_for_checkpoint(db);
  ::kill(pid, SIGINT);
  const auto stopped = wait_run(pid, d.path);
  ASSERT_EQ(stopped.rc, 75) << stopped.err;
  ASSERT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 1);
  ASSERT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 75"), 1);
  // The same six cases with the stopped one last in study order (groups and angles reversed).
  write(d.path / "t.toml", "name = \"reversed\"\n" + kSmallBase + R"(
[[group]]
name = "Ga"
set = { "fluid.viscosity" = 1.0e-2 }
[[group]]
name = "base"
[matrix]
"gravity.angle_deg" = [90, 60, 30]
)");
  const auto r = run(study_run(d.path / "t.toml", db, 1), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 7);
  bd::Database q(db.string(), bd::OpenMode::kExisting);
  auto text = [&q](const std::string& sql) {
    auto st = q.prepare(sql);
    return st.step() ? st.text(0) : std::string();
  };
  const std::string stopped_id = text("SELECT case_id FROM attempts WHERE exit_status = 75");
  EXPECT_EQ(text("SELECT case_id FROM study_cases WHERE study = 'reversed' ORDER BY position DESC LIMIT 1"),
            stopped_id);
  EXPECT_EQ(text("SELECT case_id FROM attempts WHERE exit_status IS NOT 75 ORDER BY id LIMIT 1"), stopped_id)
      << "the rerun's first attempt resumes the stopped case";
}

TEST(StudyRun, FailedCasesAreRetriedBoundedlyAndTheReasonIsRecorded) {
  TempDir d;
  write(d.path / "s.toml", R"(
name = "f"
[base.particles]
count = 1000
[base.time]
end = 0.3
average_from = 0.1
[matrix]
seed = [1, 13, 14]
)");
  const auto db = d.path / "s.db";
  auto args = study_run(d.path / "s.toml", db);
  args.insert(args.end(), {"--retries", "1"});
  const auto r = run(args, d.path, {{"FAKE_FAIL_SEED13", "1"}});
  EXPECT_EQ(r.rc, 1) << "a case failed for good";
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 2);
  // seed 13 fails once then succeeds; seed 14 fails on its first try and its one retry.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 3"), 3);
  EXPECT_EQ(
      count(db,
            "SELECT COUNT(*) FROM attempts WHERE error_text = 'error: the run became unphysical: NaN in the "
            "pressure'"),
      1);
  // A rerun does not try the exhausted case again.
  const auto again = run(args, d.path);
  EXPECT_EQ(again.rc, 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 5);
  const auto status =
      run({"study", "status", (d.path / "s.toml").string(), "--db", db.string(), "--retries", "1"}, d.path);
  EXPECT_NE(status.out.find("2 done, 0 running, 1 failed"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("alpha_f = -0.2"), std::string::npos) << status.out;
}

TEST(StudyRunBadInput, OneLineErrorNonZeroExitAndTheDatabaseUnchanged) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  ASSERT_EQ(run(study_run(d.path / "s.toml", db), d.path).rc, 0);
  {
    bd::Database c(db.string(), bd::OpenMode::kExisting);
    c.exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  const auto before = read(db);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"name = \"small\"\n[base\nscene = 1\n", "malformed TOML"},
      {"name = \"small\"\n[base.fluid]\nviscosty = 1e-3\n", "fluid.viscosty"},
      {"name = \"small\"\n[base.fluid]\nviscosity = -1e-3\n", "fluid.viscosity"},
      {"name = \"small\"\n[matrix]\n\"particles.diameter\" = [0.5e-3, 0.01]\n", "does not fit the channel"},
  };
  for (const auto& [text, expect] : bad) {
    write(d.path / "bad.toml", text);
    const auto r = run(study_run(d.path / "bad.toml", db), d.path);
    EXPECT_EQ(r.rc, 2) << text;
    EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(read(db), before) << text;
  }
  const auto unwritable = run(study_run(d.path / "s.toml", "/nonexistent_dir/sub/s.db"), d.path);
  EXPECT_NE(unwritable.rc, 0);
  EXPECT_NE(unwritable.err.find("/nonexistent_dir/sub/s.db"), std::string::npos) << unwritable.err;
  EXPECT_EQ(std::count(unwritable.err.begin(), unwritable.err.end(), '\n'), 1) << unwritable.err;

  {
    bd::Database c(db.string(), bd::OpenMode::kExisting);
    c.exec("PRAGMA user_version = 99");
    c.exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  const auto v99 = read(db);
  const auto newer = run(study_run(d.path / "s.toml", db), d.path);
  EXPECT_NE(newer.rc, 0);
  EXPECT_NE(newer.err.find("newer"), std::string::npos) << newer.err;
  EXPECT_EQ(std::count(newer.err.begin(), newer.err.end(), '\n'), 1) << newer.err;
  EXPECT_EQ(read(db), v99);
}

TEST(StudyRun, UnusableCheckpointIsSetAsideAndTheCaseRerunFromTheStart) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto ref_db = d.path / "ref.db";
  ASSERT_EQ(run(study_run(d.path / "s.toml", ref_db), d.path).rc, 0);
  const auto reference = results(ref_db);

  const auto db = d.path / "s.db";
  const pid_t pid = spawn(study_run(d.path / "s.toml", db), d.path, {{"FAKE_STEP_WALL_S", "0.1"}});
  wait_for_checkpoint(db);
  ::kill(pid, SIGINT);
  ASSERT_EQ(wait_run(pid, d.path).rc, 75);
  std::string dir;
  {
    bd::Database c(db.string(), bd::OpenMode::kExisting);
    auto st = c.prepare("SELECT run_dir FROM attempts WHERE exit_status = 75 LIMIT 1");
    ASSERT_TRUE(st.step());
    dir = st.text(0);
  }
  write(fs::path(dir) / "checkpoint.json", "{\"step\": 3, \"su");  // cut short
  const auto r = run(study_run(d.path / "s.toml", db), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 4 AND error_text LIKE '%unusable%'"),
            1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  EXPECT_EQ(results(db), reference);
  bool set_aside = false;
  for (const auto& e : fs::directory_iterator(fs::path(dir).parent_path()))
    set_aside |= e.path().filename().string().find(".bad-") != std::string::npos;
  EXPECT_TRUE(set_aside);
}

TEST(StudyRun, TwoDriversOnOneDatabaseRunEveryCaseExactlyOnce) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  fs::create_directories(d.path / "a");
  fs::create_directories(d.path / "b");
  const std::map<std::string, std::string> env = {{"FAKE_STEP_WALL_S", "0.02"}};
  const pid_t a = spawn(study_run(d.path / "s.toml", db), d.path / "a", env);
  const pid_t b = spawn(study_run(d.path / "s.toml", db), d.path / "b", env);
  const auto ra = wait_run(a, d.path / "a");
  const auto rb = wait_run(b, d.path / "b");
  EXPECT_EQ(ra.rc, 0) << ra.err;
  EXPECT_EQ(rb.rc, 0) << rb.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  // The run folder's lock keeps the second driver off a case the first one runs.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 0"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status IS NOT 0"), 0);
}

TEST(StudyRun, RenamedAndReorderedStudyRerunsNothing) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  ASSERT_EQ(run(study_run(d.path / "s.toml", db), d.path).rc, 0);
  write(d.path / "t.toml", R"(
name = "renamed"
[matrix]
"gravity.angle_deg" = [90.0, 60, 30]
[[group]]
name = "viscous"
set = { fluid = { viscosity = 0.01 } }
[[group]]
name = "reference"
[base.time]
average_from = 0.4
end = 0.8
[base]
seed = 1
particles = { count = 1000 }
)");
  const auto r = run(study_run(d.path / "t.toml", db), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("6 of 6 cases done"), std::string::npos) << r.out;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases WHERE study = 'renamed' AND group_name = 'viscous'"),
            3);
}

TEST(StudyRun, KillNineInsideTheResultTransactionLosesNothingButThatTransaction) {
  TempDir d;
  write(d.path / "s.toml", kStudy);
  const auto db = d.path / "s.db";
  // One case at a time; the driver sleeps 2 s inside its first result transaction.
  const pid_t pid = spawn(study_run(d.path / "s.toml", db, 1), d.path,
                          {{"FAKE_STEP_WALL_S", "0.01"}, {"BOYCOTT_TEST_COMMIT_DELAY_S", "2"}});
  const fs::path runs = db.string() + ".runs";
  bool finished = false;
  for (int i = 0; i < 1000 && !finished; ++i) {
    std::error_code ec;
    if (fs::exists(runs, ec))
      for (const auto& e : fs::directory_iterator(runs, ec))
        finished |= fs::exists(e.path() / "summary.json", ec);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(finished);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ::kill(pid, SIGKILL);
  wait_run(pid, d.path);
  // The transaction never committed: no result, and its attempt is still open.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 0);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE ended_at IS NULL"), 1);

  const auto r = run(study_run(d.path / "s.toml", db), d.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 6);
  // The finished case was taken from its summary.json, not run again: the attempt the killed
  // driver left open is the one that produced it, and is closed with it (6 attempts, none open).
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts"), 6);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE ended_at IS NULL"), 0);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE error_text LIKE 'abandoned%'"), 0);
}
