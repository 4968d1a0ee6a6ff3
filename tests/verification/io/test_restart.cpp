// Restart checkpoints (issue 5): a run stopped halfway and resumed ends bitwise where the
// uninterrupted run ends; bad checkpoints are refused with a message and left untouched.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "io/checkpoint_file.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"

namespace boycott {
namespace {

namespace fs = std::filesystem;

CaseParams small_case() {
  CaseParams p =
      parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/inclined_settling_smoke.toml");
  apply_override(p, "time.end=0.06");
  apply_override(p, "time.average_from=0.02");
  apply_override(p, "time.checkpoint_every=0.025");
  return p;
}

/// Runs the case in `dir`; with stop_at > 0 a stop is requested once simulated time reaches it.
int run_in(const CaseParams& p, const fs::path& dir, double stop_at = -1.0) {
  std::atomic<bool> stop{false};
  scenes::RunContext ctx;
  ctx.quiet = true;
  ctx.out_dir = dir;
  ctx.stop_requested = &stop;
  ctx.progress = [&](double t) {
    if (stop_at > 0 && t >= stop_at) stop = true;
  };
  return runs::run_case(p, ctx);
}

nlohmann::json summary(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in);
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void expect_resume_is_bitwise(const CaseParams& p, const std::string& tag) {
  const fs::path a = fs::temp_directory_path() / ("boycott_restart_a" + tag),
                 b = fs::temp_directory_path() / ("boycott_restart_b" + tag);
  fs::remove_all(a);
  fs::remove_all(b);
  ASSERT_EQ(run_in(p, a), kExitOk);
  ASSERT_EQ(run_in(p, b, 0.03), kExitInterrupted);
  EXPECT_EQ(summary(b)["status"], "interrupted");
  // The first attempt's CPU time, as its stop's checkpoint carries it.
  const auto stopped_at = io::latest_checkpoint(b);
  ASSERT_TRUE(stopped_at.has_value());
  const double carried = io::CheckpointReader(*stopped_at).scalar("run.cpu_time_s");
  EXPECT_GE(summary(b)["cpu_time_s"].get<double>(), carried);
  const auto model_names = io::CheckpointReader(*stopped_at).strings("run.model_names");
  const auto model_carried_s = io::CheckpointReader(*stopped_at).doubles("run.model_wall_time_s");
  ASSERT_EQ(run_in(p, b), kExitOk);
  const auto sa = summary(a), sb = summary(b);
  EXPECT_EQ(sb["resumed_from_checkpoint"], true);
  EXPECT_EQ(sa["mean_settling_velocity_m_s"].get<double>(), sb["mean_settling_velocity_m_s"].get<double>());
  EXPECT_EQ(sa["settling_velocity_stderr_m_s"], sb["settling_velocity_stderr_m_s"]);  // null below 5 tau_int
  EXPECT_EQ(sa["settling_velocity_correlation_time_s"], sb["settling_velocity_correlation_time_s"]);
  EXPECT_EQ(sa["cfd_steps"], sb["cfd_steps"]);
  // The final states: every particle array, every fluid field, the statistics.
  const auto fa = io::latest_checkpoint(a), fb = io::latest_checkpoint(b);
  ASSERT_TRUE(fa && fb);
  EXPECT_EQ(fa->filename(), fb->filename());
  io::CheckpointReader ra(*fa), rb(*fb);
  for (int k = 0; k < 29; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "dem.array%02d", k);
    if (!ra.has(name)) break;
    EXPECT_EQ(ra.doubles(name), rb.doubles(name)) << name;
  }
  EXPECT_EQ(ra.int64s("dem.id"), rb.int64s("dem.id"));
  for (int f = 0; f < 11; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "fluid.field.%02d", f);
    EXPECT_EQ(ra.doubles(name), rb.doubles(name)) << name;
  }
  EXPECT_EQ(ra.doubles("stats.wp.sums"), rb.doubles("stats.wp.sums"));
  EXPECT_EQ(ra.doubles("stats.pdf_w.counts"), rb.doubles("stats.pdf_w.counts"));
  // The time series has each row once, equal to the uninterrupted one.
  EXPECT_EQ(slurp(a / "timeseries.csv"), slurp(b / "timeseries.csv"));
  // What the run spent over both attempts (CPU core-seconds, each attempt's from its own start:
  // several runs share this test's process): the resumed attempt starts from what the stopped
  // one's checkpoint carried, and adds its own.
  EXPECT_GT(carried, 0.0);
  EXPECT_GT(sb["cpu_time_s"].get<double>(), carried);
  EXPECT_GT(sa["cpu_time_s"].get<double>(), 0.0);
  // Each model's wall time over both attempts too: from the start, at least what the stop's
  // checkpoint carried.
  EXPECT_EQ(sb["model_times_from_s"].get<double>(), 0.0);
  ASSERT_EQ(model_names.size(), model_carried_s.size());
  for (std::size_t k = 0; k < model_names.size(); ++k)
    EXPECT_GE(sb["models"][model_names[k]]["wall_time_s"].get<double>(), model_carried_s[k])
        << model_names[k];
}

TEST(RestartIdentity, StoppedHalfwayAndResumedEqualsTheUninterruptedRunBitwise) {
  expect_resume_is_bitwise(small_case(), "");
}

TEST(RestartIdentity, StoppedHalfwayAndResumedEqualsTheUninterruptedRunBitwiseWithPiso) {
  // PISO linearises about u^n + r (u^n - u^(n-1)): the checkpoint's two velocity levels and the
  // last step size must be enough to continue it exactly.
  CaseParams p = small_case();
  apply_override(p, "numerics.pressure_velocity_coupling=\"piso\"");
  expect_resume_is_bitwise(p, "_piso");
}

TEST(RestartIdentity, StoppedHalfwayAndResumedEqualsTheUninterruptedRunBitwiseWithTwoSimpleCorrectors) {
  // The corrector sweeps read operators assembled within the same iteration: nothing of them
  // outlives a step, so the checkpoint's state is still all a resumed run needs.
  CaseParams p = small_case();
  apply_override(p, "numerics.simple_correctors=2");
  expect_resume_is_bitwise(p, "_simple2");
}

TEST(RunFolder, WrittenBeforeAKeyWasAddedIsResumedButAnotherCaseIsRefused) {
  // A folder from an older binary: its params.json lacks the keys added since. It is the same
  // case (case_id() hashes late keys only when set), so the run resumes from its checkpoint.
  const CaseParams p = small_case();
  const fs::path d = fs::temp_directory_path() / "boycott_restart_oldkeys";
  fs::remove_all(d);
  ASSERT_EQ(run_in(p, d, 0.03), kExitInterrupted);
  nlohmann::json stored = nlohmann::json::parse(slurp(d / "params.json"));
  stored["numerics"].erase("pressure_velocity_coupling");
  stored["numerics"].erase("piso_correctors");
  std::ofstream(d / "params.json") << stored.dump(2) << "\n";
  ASSERT_EQ(run_in(p, d), kExitOk);
  EXPECT_EQ(summary(d)["resumed_from_checkpoint"], true);
  // Another case in that folder is refused, naming both ids, and nothing is overwritten.
  CaseParams other = p;
  apply_override(other, "numerics.pressure_velocity_coupling=\"piso\"");
  const std::string before = slurp(d / "summary.json");
  try {
    run_in(other, d);
    ADD_FAILURE() << "another case's folder was accepted";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("use another --out folder"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(d / "summary.json"), before);
}

TEST(RunFolder, ParamsTemporaryLeftByACrashAtTheStartIsWrittenOver) {
  // A crash during the first atomic write of params.json leaves params.json.tmp alone in the
  // folder: the run starts there (it used to be refused as a folder of someone else's, exit 4).
  const CaseParams p = small_case();
  const fs::path d = fs::temp_directory_path() / "boycott_restart_paramstmp";
  fs::remove_all(d);
  fs::create_directories(d);
  std::ofstream(d / "params.json.tmp") << "{\"scene\": \"inclined_sett";
  ASSERT_EQ(run_in(p, d), kExitOk);
  EXPECT_FALSE(fs::exists(d / "params.json.tmp"));
  CaseParams resolved = p;
  validate(resolved);
  EXPECT_EQ(case_id(case_from_json(nlohmann::json::parse(slurp(d / "params.json")))), case_id(resolved));
  EXPECT_EQ(summary(d)["status"], "completed");
}

TEST(BadCheckpoint, TruncatedFileIsRefusedAndLeftInPlace) {
  const CaseParams p = small_case();
  const fs::path d = fs::temp_directory_path() / "boycott_restart_trunc";
  fs::remove_all(d);
  ASSERT_EQ(run_in(p, d, 0.03), kExitInterrupted);
  const auto all = io::checkpoints_newest_first(d);
  ASSERT_EQ(all.size(), 2u);  // t = 0.025 (the schedule) and 0.03 (the stop)
  const auto ck = all.front();
  const auto size = fs::file_size(ck);
  fs::resize_file(ck, size / 2);
  // The only checkpoint: refused, naming it, and left as it is.
  fs::remove(all.back());
  try {
    run_in(p, d);
    FAIL() << "a truncated checkpoint was accepted";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find(ck.filename().string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::file_size(ck), size / 2);  // not overwritten, not deleted
  EXPECT_FALSE(fs::exists(d / "summary.json") && summary(d)["status"] == "completed");
}

TEST(BadCheckpoint, TruncatedNewestIsSetAsideAndTheRunResumesFromTheOlderOne) {
  const CaseParams p = small_case();
  const fs::path ref = fs::temp_directory_path() / "boycott_restart_trunc_ref",
                 d = fs::temp_directory_path() / "boycott_restart_trunc_older";
  fs::remove_all(ref);
  fs::remove_all(d);
  ASSERT_EQ(run_in(p, ref), kExitOk);
  ASSERT_EQ(run_in(p, d, 0.03), kExitInterrupted);
  const auto ck = *io::latest_checkpoint(d);
  const auto size = fs::file_size(ck);
  fs::resize_file(ck, size / 2);
  ASSERT_EQ(run_in(p, d), kExitOk);
  EXPECT_EQ(fs::file_size(ck.string() + ".bad"), size / 2);  // kept aside, never deleted
  EXPECT_EQ(summary(d)["mean_settling_velocity_m_s"], summary(ref)["mean_settling_velocity_m_s"]);
  EXPECT_EQ(summary(d)["dem_steps"], summary(ref)["dem_steps"]);
  EXPECT_EQ(slurp(d / "timeseries.csv"), slurp(ref / "timeseries.csv"));
}

TEST(BadCheckpoint, CheckpointOfOtherParametersIsRefused) {
  CaseParams p = small_case();
  const fs::path d = fs::temp_directory_path() / "boycott_restart_other";
  fs::remove_all(d);
  ASSERT_EQ(run_in(p, d, 0.03), kExitInterrupted);
  const auto ck = io::latest_checkpoint(d);
  // Another case in the same folder: refused by params.json already; without params.json the
  // folder is no run folder any more (refused, untouched); a lone checkpoint of another case in
  // an otherwise empty folder is refused by the checkpoint's own parameters.
  apply_override(p, "gravity.angle_deg=70");
  EXPECT_THROW(run_in(p, d), CheckpointError);
  fs::remove(d / "params.json");
  try {
    run_in(p, d);
    FAIL() << "a folder without params.json was written into";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("has no params.json"), std::string::npos) << e.what();
  }
  const fs::path lone = fs::temp_directory_path() / "boycott_restart_other_lone";
  fs::remove_all(lone);
  fs::create_directories(lone / "checkpoints");
  fs::copy_file(*ck, lone / "checkpoints" / ck->filename());
  try {
    run_in(p, lone);
    FAIL() << "a checkpoint of another case was accepted";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("belongs to case"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(*ck));
  EXPECT_TRUE(fs::exists(lone / "checkpoints" / ck->filename()));
}

}  // namespace
}  // namespace boycott
