// A study too large to hold (issue 62: 81 angles x 10 viscosities x 13 densities x 10 diameters x
// 10 seeds = 1 053 000 cases) through the real `boycott` binary under an address-space limit
// (RLIMIT_AS) of 256 MiB, about 100 MiB above what the binary needs to load its libraries: plan,
// status, run, submit and collect refuse it with one sentence naming the count and the limit,
// exit 2, before the study is expanded (expanding it took over 1.3 GB) and before anything is
// written. The time and memory of studies up to the limit: docs/performance.md, "Large studies".
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "driver/store/database.hpp"
#include "study_process.hpp"

namespace {

using namespace study_process;

constexpr rlim_t kAddressSpaceBytes = 256ull << 20;  // 256 MiB

/// `count` values from `first` in steps of `step`, as a TOML array.
std::string values(double first, double step, int count) {
  std::string s = "[";
  for (int i = 0; i < count; ++i) s += (i ? ", " : "") + std::to_string(first + step * i);
  return s + "]";
}

std::string big_study() {
  return "name = \"big\"\n[base]\nscene = \"inclined_settling\"\n[matrix]\n"
         "\"gravity.angle_deg\" = " +
         values(10, 1, 81) + "\n\"fluid.viscosity\" = " + values(1e-3, 1e-3, 10) +
         "\n\"particles.density\" = " + values(1500, 50, 13) +
         "\n\"particles.diameter\" = " + values(4e-4, 2e-5, 10) +
         "\nseed = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n";
}

/// The command under the limit; its exit status and output.
study_process::Run limited(const std::vector<std::string>& args, const fs::path& dir) {
  return wait_run(spawn(args, dir, {}, BOYCOTT_BIN, kAddressSpaceBytes), dir);
}

}  // namespace

TEST(LargeStudy, AStudyOfAMillionCasesIsRefusedInOneSentenceUnderAMemoryLimitWritingNothing) {
  TempDir d;
  const auto study = (d.path / "big.toml").string();
  write(study, big_study());
  // An existing database the refused commands must leave as it is.
  const auto kept = d.path / "kept.db";
  { boycott::driver::Database db(kept.string(), boycott::driver::OpenMode::kCreate); }
  const std::string kept_bytes = read(kept);
  const auto fresh = (d.path / "fresh.db").string();
  const std::vector<std::vector<std::string>> commands = {
      {"study", "plan", study},
      {"study", "plan", study, "--format", "json"},
      {"study", "run", study, "--db", fresh, "--solver-command", kSolver},
      {"study", "status", study, "--db", kept.string()},
      {"study", "submit", study, "--db", fresh, "--scheduler", "slurm", "--dry-run"},
      {"study", "collect", study, "--db", fresh}};
  for (const auto& args : commands) {
    const auto r = limited(args, d.path);
    const std::string what = args[1];
    EXPECT_EQ(r.rc, 2) << what << ": " << r.err;
    EXPECT_EQ(r.err,
              "error: study 'big' expands to 1053000 cases, more than the 100000 a study may hold: split it "
              "into several studies\n")
        << what;
    EXPECT_TRUE(r.out.empty()) << what << ": " << r.out;
  }
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_FALSE(fs::exists(fresh + ".runs"));
  EXPECT_EQ(read(kept), kept_bytes);
}
