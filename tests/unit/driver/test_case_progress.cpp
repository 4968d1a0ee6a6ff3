// CaseProgress and the study's progress on a clock the test moves: lines are due by wall time,
// so the test owns the clock (no test may judge the machine's speed).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "driver/cli/case_progress.hpp"
#include "driver/run/progress.hpp"

namespace bd = boycott::driver;
using Clock = bd::CaseProgress::Clock;

namespace {
struct FakeTerminal {
  Clock::time_point now{};
  std::vector<std::string> out;
  bd::CaseProgress::Io io() {
    return {[this] { return now; }, [this](const std::string& s) { out.push_back(s); }};
  }
  void advance(double s) {
    now += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
};
}  // namespace

TEST(CaseProgress, PlainLinesComeEveryProgressEverySecondsOfWallTime) {
  FakeTerminal term;
  bd::CaseProgress p(1.0, false, 0.5, term.io());
  // 0.2 wall s per 0.01 simulated s over 40 steps: 8 wall s, a line each 0.5 s past the first at()
  // (steps land on 0.2 s ticks, so a line is due every third step: at 0.6, 1.2, ... 7.8 s).
  for (int k = 0; k <= 40; ++k) {
    p.at(0.01 * k);
    term.advance(0.2);
  }
  ASSERT_EQ(term.out.size(), 13u);
  for (const auto& l : term.out) {
    EXPECT_EQ(l.rfind("progress: t = ", 0), 0u) << l;
    EXPECT_NE(l.find("20 wall s per simulated s"), std::string::npos) << l;
  }
  p.finish();  // not a terminal: nothing more (the outcome line is the caller's)
  EXPECT_EQ(term.out.size(), 13u);
}

TEST(CaseProgress, EtaFollowsTheRecentRateNotTheWholeRun) {
  FakeTerminal term;
  bd::CaseProgress p(20.0, false, 1.0, term.io());
  // 100 s of cheap start (1 wall s per 0.1 simulated s), then 10x slower for 100 wall s.
  double t = 0.0;
  for (int k = 0; k < 100; ++k) p.at(t), t += 0.1, term.advance(1.0);
  for (int k = 0; k < 100; ++k) p.at(t), t += 0.01, term.advance(1.0);
  p.at(t);
  // The last 50 wall s (a quarter of the run) ran at 100 wall s per simulated s: 9 simulated s
  // left take 900 s (the whole run's mean rate, 18.2, would say 164 s).
  const std::string& last = term.out.back();
  EXPECT_NE(last.find("100 wall s per simulated s, ETA 15m00s"), std::string::npos) << last;
}

TEST(CaseProgress, TheFinishedLiveLineShowsTheWallTimeAndNoEta) {
  FakeTerminal term;
  bd::CaseProgress p(1.0, true, 30.0, term.io());
  for (int k = 0; k <= 10; ++k) p.at(0.1 * k), term.advance(1.0);
  ASSERT_FALSE(term.out.empty());
  EXPECT_NE(term.out.back().find("ETA"), std::string::npos);
  p.finish();
  const std::string& last = term.out.back();
  EXPECT_EQ(last.find("ETA"), std::string::npos) << last;
  EXPECT_NE(last.find("11s wall"), std::string::npos) << last;
  EXPECT_EQ(last.back(), '\n');
}

TEST(StudyProgress, TheFirstEtaIsThePlansUntilACaseReportsARate) {
  // 4 cases pending on 2 jobs at the plan's 100 s each: 200 s, the plan's study estimate.
  bd::ProgressDisplay display("s", 2, false, 1.0);
  std::map<std::string, bd::PlannedCase> plan;
  for (const char* id : {"a", "b", "c", "d"}) plan[id] = {100.0, 0.0, 10.0};
  display.set_plan(plan);
  bd::ProgressCounts counts;
  counts.pending = 4;
  testing::internal::CaptureStderr();
  display.draw(counts, {});
  std::string line = testing::internal::GetCapturedStderr();
  EXPECT_NE(line.find("4 pending; ETA 3m20s"), std::string::npos) << line;
  // A finished case's own time replaces the plan's mean for cases the counts do not name: 3 left
  // at 60 s on 2 jobs.
  display.add_finished_case("a", 60.0, 0.0);
  counts.pending = 3;
  counts.done = 1;
  testing::internal::CaptureStderr();
  display.draw(counts, {});
  line = testing::internal::GetCapturedStderr();
  EXPECT_NE(line.find("3 pending; ETA 1m30s"), std::string::npos) << line;
}

namespace {
/// A case of a study, running in a run folder of its own whose time series the test writes.
struct FolderCase {
  std::filesystem::path dir;
  bd::StudyCase c;
  bd::RunningCase run;
  /// Started at `started_wall_s` after the clock's zero, from simulated time 0.
  FolderCase(const std::string& id, double end_s, double started_wall_s)
      : dir(std::filesystem::temp_directory_path() / ("boycott_study_progress_" + id)) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    // (from std::string, not a literal: GCC 12 warns a false -Wrestrict on assigning a short one)
    c.group = std::string("g");
    c.id = id;
    c.params.time.end_s = end_s;
    run.c = &c;
    run.dir = dir;
    run.started = at(started_wall_s);
    run.t_start_s = 0.0;
  }
  FolderCase(const FolderCase&) = delete;
  FolderCase& operator=(const FolderCase&) = delete;
  ~FolderCase() { std::filesystem::remove_all(dir); }
  /// The solver's last row: simulated time t_s.
  void reached(double t_s) const {
    std::ofstream(dir / "timeseries.csv") << "t_s,mean_wp_m_s\n" << t_s << ",-0.1\n";
  }
  static bd::RecentRate::Clock::time_point at(double wall_s) {
    return bd::RecentRate::Clock::time_point{} +
           std::chrono::duration_cast<bd::RecentRate::Clock::duration>(std::chrono::duration<double>(wall_s));
  }
};

/// The progress block drawn at `wall_s` after the clock's zero.
std::string drawn(bd::ProgressDisplay& display, const bd::ProgressCounts& counts,
                  const std::vector<bd::RunningCase>& running, double wall_s) {
  testing::internal::CaptureStderr();
  display.draw_at(counts, running, FolderCase::at(wall_s));
  return testing::internal::GetCapturedStderr();
}
}  // namespace

TEST(StudyProgress, ARunningCasesRateIsItsRecentOneSoAPauseAgesOut) {
  // A case at 0.001 simulated s per wall s, paused for an hour (a campaign stopped for a
  // benchmark), then running again: once the pause is older than a quarter of the attempt, the
  // rate shown is the running one again, not the attempt's mean.
  const FolderCase f("0123456789abcdef", 10.0, 3600.0);
  bd::ProgressDisplay display("s", 1, false, 1.0);
  const bd::ProgressCounts counts;
  auto draw = [&](double wall_s, double t_s) {
    f.reached(t_s);
    return drawn(display, counts, {f.run}, 3600.0 + wall_s);
  };
  EXPECT_NE(draw(1000, 1.0).find("0.0010 sim s/s"), std::string::npos);
  draw(4600, 1.0);                             // an hour without progress
  const std::string during = draw(5000, 1.4);  // running again: the pause still counts
  EXPECT_NE(during.find("0.0001 sim s/s"), std::string::npos) << during;
  draw(6000, 2.4);
  // At 6 200 s the window is 1 550 s: it starts at the pause's end (4 600 s, t = 1.0).
  const std::string after = draw(6200, 2.6);
  EXPECT_NE(after.find("0.0010 sim s/s"), std::string::npos) << after;
  // 7.4 simulated s left at 0.001: 7 400 s (the attempt's mean rate, 0.00042, would say 4h54m).
  EXPECT_NE(after.find("ETA 2h03m"), std::string::npos) << after;
}

TEST(StudyProgress, EachPendingCaseIsPricedByItsOwnPlanAtTheRateTheCasesRunAgainstIt) {
  // A study's cases differ several-fold (a 405 000-particle case against a 120 000 one): a mean
  // case misprices them. The plan: "cheap" 100 s for 0-10 simulated s, "dear" 400 s.
  const FolderCase cheap("cheap", 10.0, 0.0);
  bd::ProgressDisplay display("s", 1, false, 1.0);
  display.set_plan({{"cheap", {100.0, 0.0, 10.0}}, {"dear", {400.0, 0.0, 10.0}}});
  bd::ProgressCounts counts;
  counts.pending = 2;
  counts.pending_ids = {"cheap", "dear"};
  // Nothing ran yet: the plan's sum, 500 s on 1 job.
  std::string out = drawn(display, counts, {}, 0.0);
  EXPECT_NE(out.find("2 pending; ETA 8m20s"), std::string::npos) << out;
  // "cheap" runs at 20 wall s per simulated s, twice its plan's 10: at t = 5 s its 5 s left take
  // 100 s, and "dear" is priced at twice its plan, 800 s: 900 s (a mean case of 20 x 10 = 200 s
  // would say 300 s).
  counts.pending = 1;
  counts.pending_ids = {"dear"};
  cheap.reached(5.0);
  out = drawn(display, counts, {cheap.run}, 100.0);
  EXPECT_NE(out.find("1 pending; ETA 15m00s"), std::string::npos) << out;
  // Stopped at t = 5 s, "cheap" is pending again, for the 5 simulated s it has left: the same.
  counts.pending = 2;
  counts.pending_ids = {"cheap", "dear"};
  counts.stopping = true;
  out = drawn(display, counts, {}, 101.0);
  EXPECT_NE(out.find("2 pending; ETA 15m00s (stopping)"), std::string::npos) << out;
}
