// [refine] through the real `boycott` binary against fake_solver.py with a peak at 64 deg
// (FAKE_PEAK_DEG): points added after the listed ones finish, recorded with why, the same points
// whatever order the cases finished in, after a kill -9 between rounds or while a point is being
// chosen, and with two drivers on one database; replicas of added points; query peak.
#include <chrono>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "driver/store/database.hpp"
#include "study_process.hpp"

namespace {

using namespace study_process;
namespace bd = boycott::driver;
namespace fs = std::filesystem;

// 5 listed angles, 8 fake steps each; the fake curve peaks at 64 deg.
const char* kStudy = R"(
name = "peak"
refine = { key = "gravity.angle_deg", objective = "max_abs_settling", resolution = 2.5, max_points = 3 }
matrix = { "gravity.angle_deg" = [30, 45, 60, 75, 90] }
base = { scene = "inclined_settling", seed = 1, particles = { count = 1000 }, time = { end = 0.8, average_from = 0.4 } }
[[group]]
name = "base"
@REPLICAS@
)";

std::string study_text(int replicas = 1) {
  std::string s = kStudy;
  s.replace(s.find("@REPLICAS@"), 10, replicas > 1 ? "replicas = " + std::to_string(replicas) : "");
  return s;
}

const std::map<std::string, std::string> kPeakEnv = {{"FAKE_PEAK_DEG", "64"}};

/// (round, value, case id) of every added point, by round.
using Points = std::vector<std::tuple<int, double, std::string>>;

/// Read without writing (a read-only connection does not wait for a driver's write transaction).
Points added_points(const fs::path& db) {
  bd::Database d(db.string(), bd::OpenMode::kReadOnly);
  auto st = d.prepare("SELECT round, value, case_id, reason FROM refined_points ORDER BY round");
  Points out;
  while (st.step()) {
    EXPECT_FALSE(st.text(3).empty()) << "every added point says why";
    out.emplace_back(static_cast<int>(st.integer(0)), st.real(1), st.text(2));
  }
  return out;
}

/// 0 while the driver has not made the database yet.
std::int64_t count_now(const fs::path& db, const std::string& sql) {
  try {
    bd::Database d(db.string(), bd::OpenMode::kReadOnly);
    auto st = d.prepare(sql);
    st.step();
    return st.integer(0);
  } catch (const bd::DatabaseError&) {
    return 0;
  }
}

/// Waits (up to ~60 s) until sql counts at least n.
void wait_for(const fs::path& db, const std::string& sql, std::int64_t n) {
  for (int i = 0; i < 3000 && count_now(db, sql) < n; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

/// Starts `study run` on d's s.db, kills it (-9) `after_ms` after `sql` counts `n`, and waits for it.
void kill_study_run_once(const TempDir& d, const std::map<std::string, std::string>& env,
                         const std::string& sql, std::int64_t n, int after_ms) {
  const auto db = d.path / "s.db";
  const pid_t pid = spawn(study_run(d.path / "s.toml", db, 2), d.path, env);
  wait_for(db, sql, n);
  std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
  ::kill(pid, SIGKILL);
  wait_run(pid, d.path);
}

/// The uninterrupted study's added points (jobs 1: the cases finish in study order).
Points reference_points(const TempDir& d) {
  write(d.path / "s.toml", study_text());
  const auto db = d.path / "ref.db";
  const auto r = run(study_run(d.path / "s.toml", db, 1), d.path, kPeakEnv);
  EXPECT_EQ(r.rc, 0) << r.err;
  return added_points(db);
}

/// Each test's scratch folder with the study file and the points its uninterrupted run adds.
class RefineRun : public ::testing::Test {
 protected:
  void SetUp() override {
    reference = reference_points(d);
    ASSERT_GE(reference.size(), 1u);
  }
  TempDir d;
  Points reference;
  fs::path db = d.path / "s.db";
};

}  // namespace

TEST_F(RefineRun, AddsPointsAroundThePeakTheSameWhateverOrderTheCasesFinish) {
  ASSERT_LE(reference.size(), 3u);
  for (const auto& [round, value, id] : reference) {
    EXPECT_GT(value, 45.0);
    EXPECT_LT(value, 75.0);
  }
  // --jobs 3: the listed cases finish in another order; the same points are added.
  const auto r = run(study_run(d.path / "s.toml", db, 3), d.path, kPeakEnv);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(added_points(db), reference);
  EXPECT_NE(r.err.find("refine: group base: round 1 adds gravity.angle_deg = "), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("peak (query peak):"), std::string::npos) << r.out;
  // Added points are ordinary cases of the study, with results.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases WHERE study = 'peak'"), 5 + std::ssize(reference));
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results r JOIN refined_points p ON p.case_id = r.case_id"),
            std::ssize(reference));

  const auto q = run({"query", "peak", "--db", db.string(), "--study", "peak", "--format", "json"}, d.path);
  ASSERT_EQ(q.rc, 0) << q.err;
  const auto rows = nlohmann::json::parse(q.out);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["group"], "base");
  EXPECT_NEAR(rows[0]["angle_deg"].get<double>(), 64.0, 2.5) << q.out;
  EXPECT_EQ(rows[0]["n_points"], 5 + std::ssize(reference));
  EXPECT_EQ(rows[0]["n_added"], std::ssize(reference));
  EXPECT_LT(rows[0]["mean_settling_velocity_m_s"].get<double>(), 0.0);
  EXPECT_GT(rows[0]["r_acc"].get<double>(), 1.0);
  for (const char* key : {"angle_err_deg", "error_m_s", "r_acc_err", "resolved", "status", "why"})
    EXPECT_TRUE(rows[0].contains(key)) << key;

  // Status, plan and the plot know the added points.
  const auto status = run({"study", "status", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  EXPECT_NE(status.out.find(std::to_string(5 + reference.size()) +
                            " cases: " + std::to_string(5 + reference.size()) + " done"),
            std::string::npos)
      << status.out;
  const auto plan = run({"study", "plan", (d.path / "s.toml").string(), "--db", db.string()}, d.path);
  EXPECT_NE(plan.out.find("[refine] may add at most"), std::string::npos) << plan.out;
  const auto svg =
      run({"query", "curve", "--db", db.string(), "--study", "peak", "--plot", (d.path / "c.svg").string()},
          d.path);
  ASSERT_EQ(svg.rc, 0) << svg.err;
  // A second run adds nothing.
  const auto again = run(study_run(d.path / "s.toml", db, 2), d.path, kPeakEnv);
  ASSERT_EQ(again.rc, 0) << again.err;
  EXPECT_EQ(added_points(db), reference);
}

TEST_F(RefineRun, KilledWhileChoosingAPointOrBetweenRoundsResumesWithTheSamePoints) {
  // Killed while the first point is being chosen: the test hook holds the transaction that
  // records it open for 2 s once the listed cases are done.
  auto env = kPeakEnv;
  env["BOYCOTT_TEST_REFINE_DELAY_S"] = "2";
  kill_study_run_once(d, env, "SELECT COUNT(*) FROM results", 5, 500);
  EXPECT_EQ(count_now(db, "SELECT COUNT(*) FROM refined_points"), 0)
      << "the kill landed inside the transaction";
  // Killed between rounds: once the first point is recorded (its case running or done).
  kill_study_run_once(d, kPeakEnv, "SELECT COUNT(*) FROM refined_points", 1, 0);
  EXPECT_GE(count_now(db, "SELECT COUNT(*) FROM refined_points"), 1);
  // The solvers the kill orphaned stop on their own (parent death); the rerun waits for their locks.
  const auto r = run(study_run(d.path / "s.toml", db, 2), d.path, kPeakEnv);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(added_points(db), reference);
}

TEST_F(RefineRun, TwoDriversOnOneDatabaseAddEachPointOnce) {
  fs::create_directories(d.path / "a");
  fs::create_directories(d.path / "b");
  const pid_t a = spawn(study_run(d.path / "s.toml", db, 1), d.path / "a", kPeakEnv);
  const pid_t b = spawn(study_run(d.path / "s.toml", db, 1), d.path / "b", kPeakEnv);
  const auto ra = wait_run(a, d.path / "a"), rb = wait_run(b, d.path / "b");
  ASSERT_EQ(ra.rc, 0) << ra.err;
  ASSERT_EQ(rb.rc, 0) << rb.err;
  EXPECT_EQ(added_points(db), reference);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases"), 5 + std::ssize(reference));
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 5 + std::ssize(reference));
  // Each case ran once: its one successful attempt.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM attempts WHERE exit_status = 0"), 5 + std::ssize(reference));
}

TEST(RefineReplicas, AddedPointsRunWithTheGroupsReplicas) {
  TempDir d;
  write(d.path / "s.toml", study_text(2));
  const auto db = d.path / "s.db";
  const auto r = run(study_run(d.path / "s.toml", db, 2), d.path, kPeakEnv);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto points = added_points(db);
  ASSERT_GE(points.size(), 1u);
  // Every point, listed or added, with its two replicas (seeds 1 and 2).
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM study_cases"), 2 * (5 + std::ssize(points)));
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM results"), 2 * (5 + std::ssize(points)));
  const auto q = run({"query", "curve", "--db", db.string(), "--study", "peak", "--format", "json"}, d.path);
  for (const auto& p : nlohmann::json::parse(q.out)) EXPECT_EQ(p["n_replicas"], 2) << p;
}
