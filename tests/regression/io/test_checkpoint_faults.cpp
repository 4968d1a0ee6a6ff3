// Fault injection on the checkpoints of a real coupled run (issue 26), through the `boycott`
// binary: flipped bytes, a checkpoint written before checkpoints carried a hash, a state that
// fails validation, a disk that fills up part-way. Nothing lost and nothing wrong: every damaged
// checkpoint is refused (by its hash, in milliseconds) or resumes to the bitwise-identical result,
// and a resumed run ends where the uninterrupted one ends.
#include <fcntl.h>
#include <hdf5.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "io/checkpoint_file.hpp"

namespace {

namespace fs = std::filesystem;
namespace io = boycott::io;

const std::string kCase = std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/inclined_settling_smoke.toml";
// Checkpoints at t = 0.02, 0.04 and 0.06 (the end), all three kept.
const std::vector<std::string> kSets = {
    "--set", "time.end=0.06", "--set", "time.average_from=0.02", "--set", "time.checkpoint_every=0.02"};

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void spill(const fs::path& f, const std::string& bytes) {
  std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes;
}

struct CaseRun {
  int rc = -1;
  std::string err;
};

/// `boycott case run` of the smoke case into `out`; stderr comes back (kept in /tmp: a helper
/// process of Open MPI may hold it a moment after the solver exits).
CaseRun run_case(const fs::path& out) {
  static int runs = 0;
  const fs::path err = fs::temp_directory_path() / ("boycott_ckpt_faults_" + std::to_string(getpid()) + "_" +
                                                    std::to_string(runs++) + ".stderr");
  const pid_t pid = fork();
  if (pid == 0) {
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    // The child's output goes nowhere if these fail: nothing to report from here.
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen(err.c_str(), "w", stderr)) _exit(127);
    std::vector<std::string> args = {BOYCOTT_BIN, "case", "run", kCase, "--out", out.string(), "--quiet"};
    args.insert(args.end(), kSets.begin(), kSets.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(BOYCOTT_BIN, argv.data());
    _exit(127);
  }
  int st = 0;
  waitpid(pid, &st, 0);
  CaseRun r;
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.err = slurp(err);
  fs::remove(err);
  return r;
}

/// Empty when run folders a and b hold the same result: the time series and PDFs byte for byte,
/// every summary value but wall and CPU times, timers and whether it was resumed.
std::string difference(const fs::path& a, const fs::path& b) {
  for (const char* f : {"timeseries.csv", "pdf_y.csv", "pdf_wp.csv"})
    if (slurp(a / f) != slurp(b / f)) return std::string(f) + " differs";
  auto sa = nlohmann::json::parse(slurp(a / "summary.json"));
  auto sb = nlohmann::json::parse(slurp(b / "summary.json"));
  // What belongs to one attempt (its cost, its list rebuilds), not to the result.
  for (const char* k :
       {"wall_time_s", "wall_time_per_simulated_second_s", "attempt_cpu_time_s", "cpu_time_s", "models",
        "model_times_from_s", "ranks", "resumed_from_checkpoint", "neighbor_rebuilds_this_attempt"}) {
    sa.erase(k);
    sb.erase(k);
  }
  for (const auto& [k, v] : sa.items())
    if (!sb.contains(k) || sb[k] != v) return "summary." + k + " differs";
  return sa.size() == sb.size() ? "" : "summary keys differ";
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

class CheckpointFaults : public ::testing::Test {
 protected:
  // One uninterrupted run for every test: the result all the others must reproduce.
  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/boycott_ckpt_faults_XXXXXX";
    root_ = mkdtemp(tmpl);
    const CaseRun r = run_case(root_ / "reference");
    ASSERT_EQ(r.rc, 0) << r.err;
    ASSERT_EQ(io::checkpoints_newest_first(root_ / "reference").size(), 3u);
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static fs::path reference() { return root_ / "reference"; }
  /// A copy of the reference run folder, to damage, as a run killed after its last checkpoint
  /// leaves it: without its summary (a finished run is not resumed, only reported complete).
  static fs::path copy_of_reference(const std::string& name) {
    const fs::path d = root_ / name;
    fs::remove_all(d);
    fs::copy(reference(), d, fs::copy_options::recursive);
    fs::remove(d / "summary.json");
    return d;
  }
  static fs::path ckpt(const fs::path& run, int step) { return io::checkpoint_path(run, step); }

  static inline fs::path root_;
};

/// Opens a checkpoint for editing as HDF5: its hash footer cut off first (81 bytes).
hid_t open_for_edit(const fs::path& f) {
  fs::resize_file(f, fs::file_size(f) - 81);
  return H5Fopen(f.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
}

/// Writes `values` over a dataset of doubles of a checkpoint and seals it again (its hash right):
/// a value planted on purpose. False when the file or dataset cannot be written.
bool overwrite_sealed(const fs::path& file, const char* dataset, const std::vector<double>& values) {
  const hid_t f = open_for_edit(file);
  if (f < 0) return false;
  const hid_t ds = H5Dopen2(f, dataset, H5P_DEFAULT);
  const bool ok =
      ds >= 0 && H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0;
  if (ds >= 0) H5Dclose(ds);
  H5Fclose(f);
  io::seal_file(file);
  return ok;
}

TEST_F(CheckpointFaults, HundredFlippedBytesAreRefusedByTheHashOrResumeBitwise) {
  const fs::path newest = ckpt(reference(), 60);
  const std::string good = slurp(newest);
  const std::size_t size = good.size();
  // Half anywhere (mostly data), a quarter in the first 4 KiB (superblock, root group) and a
  // quarter in the last 4 KiB (object headers and heaps HDF5 writes last, the hash footer).
  std::mt19937_64 rng(26);
  std::vector<std::size_t> offsets;
  for (int i = 0; i < 50; ++i) offsets.push_back(rng() % size);
  for (int i = 0; i < 25; ++i) offsets.push_back(rng() % 4096);
  for (int i = 0; i < 25; ++i) offsets.push_back(size - 1 - rng() % 4096);

  int refused = 0, identical = 0, wrong = 0, accepted_unchecked = 0, resumes = 0;
  double slowest_ms = 0, total_ms = 0;
  const fs::path probe = root_ / "probe.h5";
  std::vector<std::string> accepted;
  for (const std::size_t off : offsets) {
    std::string bad = good;
    bad[off] = static_cast<char>(bad[off] ^ static_cast<char>(1 + rng() % 255));
    spill(probe, bad);
    const auto t0 = std::chrono::steady_clock::now();
    try {
      io::CheckpointReader r(probe);
      accepted.push_back(bad);
    } catch (const boycott::CheckpointError& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("SHA-256"), std::string::npos)
          << "not refused by the hash: " << e.what();
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    slowest_ms = std::max(slowest_ms, ms);
    total_ms += ms;
  }
  // Any file the reader accepted must resume to the uninterrupted result (at most 5 real
  // resumes: the hash leaves none in practice).
  for (const std::string& bad : accepted) {
    if (resumes == 5) {
      ++accepted_unchecked;
      continue;
    }
    const fs::path d = copy_of_reference("accepted_" + std::to_string(resumes));
    spill(ckpt(d, 60), bad);
    const CaseRun r = run_case(d);
    ++resumes;
    (r.rc == 0 && difference(reference(), d).empty()) ? ++identical : ++wrong;
  }
  // Two refused files through the solver itself: the run falls back to the next older
  // checkpoint, keeps the refused one aside and ends bitwise where the reference ends.
  for (const std::size_t off : {offsets[0], offsets[50]}) {
    const fs::path d = copy_of_reference("refused_" + std::to_string(off));
    std::string bad = good;
    bad[off] = static_cast<char>(bad[off] ^ 0x01);
    spill(ckpt(d, 60), bad);
    const CaseRun r = run_case(d);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("checkpoint refused: checkpoint " + ckpt(d, 60).string()), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("SHA-256"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(ckpt(d, 60).string() + ".bad"), bad) << "the refused file is kept aside as it was";
    EXPECT_EQ(difference(reference(), d), "") << "resumed from the older checkpoint";
  }
  std::printf(
      "[ report ] %zu trials (flipped byte at random offsets of a %zu-byte checkpoint, 50 anywhere, 25 in "
      "the first and 25 in the last 4 KiB): %d refused by the hash (mean %.1f ms, slowest %.1f ms), %d "
      "accepted and resumed identical, %d wrong, %d accepted unchecked; 2 refused ones resumed from the "
      "older checkpoint, identical\n",
      offsets.size(), size, refused, total_ms / offsets.size(), slowest_ms, identical, wrong,
      accepted_unchecked);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(accepted_unchecked, 0);
  EXPECT_EQ(refused + identical, static_cast<int>(offsets.size()));
}

TEST_F(CheckpointFaults, CheckpointWrittenBeforeHashesIsResumedAsUnverifiedSaidOnce) {
  const fs::path d = copy_of_reference("legacy");
  fs::remove(ckpt(d, 60));
  // As earlier builds wrote it: no footer, no attribute that claims one.
  const hid_t f = open_for_edit(ckpt(d, 40));
  ASSERT_GE(f, 0);
  ASSERT_GE(H5Adelete(f, "sha256_footer"), 0);
  H5Fclose(f);
  EXPECT_EQ(io::verify_file(ckpt(d, 40)), io::Integrity::kUnverified);
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(count(r.err, "unverified"), 1u) << r.err;
  EXPECT_EQ(count(r.err, "refused"), 0u) << r.err;
  EXPECT_EQ(difference(reference(), d), "");
}

// Checkpoints of builds before runs carried their CPU time: the run resumes bit for bit, and
// its summary says the total is unknown (null) instead of counting only the last attempt's.
TEST_F(CheckpointFaults, CheckpointWithoutCpuTimeResumesWithTheRunsCpuTimeUnknown) {
  const fs::path d = copy_of_reference("no_cpu_time");
  fs::remove(ckpt(d, 60));
  EXPECT_GT(nlohmann::json::parse(slurp(reference() / "summary.json"))["cpu_time_s"].get<double>(), 0.0);
  const hid_t f = open_for_edit(ckpt(d, 40));
  ASSERT_GE(f, 0);
  ASSERT_GE(H5Adelete(f, "sha256_footer"), 0);
  ASSERT_GE(H5Ldelete(f, "run.cpu_time_s", H5P_DEFAULT), 0);
  H5Fclose(f);
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(difference(reference(), d), "");
  const auto s = nlohmann::json::parse(slurp(d / "summary.json"));
  EXPECT_TRUE(s["cpu_time_s"].is_null());
  EXPECT_GT(s["attempt_cpu_time_s"].get<double>(), 0.0);
}

// The CPU time a checkpoint carries is the earlier attempts': the resumed run adds its own to
// it. Set to 10^6 core-s on purpose (the file sealed again), the total must lie between that and
// that plus the whole resumed process's CPU time, whatever the machine's speed.
TEST_F(CheckpointFaults, TheCpuTimeACheckpointCarriesIsAddedToTheResumedAttempts) {
  const fs::path d = copy_of_reference("cpu_carried");
  fs::remove(ckpt(d, 60));
  const double carried = 1e6;
  ASSERT_TRUE(overwrite_sealed(ckpt(d, 40), "run.cpu_time_s", {carried}));
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(difference(reference(), d), "");
  const auto s = nlohmann::json::parse(slurp(d / "summary.json"));
  EXPECT_GE(s["cpu_time_s"].get<double>(), carried);
  EXPECT_LE(s["cpu_time_s"].get<double>(), carried + s["attempt_cpu_time_s"].get<double>());
}

// Each model's wall time a checkpoint carries is the earlier attempts': the resumed run adds its
// own, so the summary's `models` cover the whole run (model_times_from_s 0), while each rank's
// phase seconds are this attempt's (ranks.seconds_from_s: the resume point; another attempt may
// have run on other ranks). Set to 10^6 s each on purpose (the file sealed again), each model's
// total must lie between that and that plus the resumed attempt's wall time, whatever the machine.
TEST_F(CheckpointFaults, TheModelTimesACheckpointCarriesAreAddedToTheResumedAttempts) {
  const auto whole = nlohmann::json::parse(slurp(reference() / "summary.json"));
  EXPECT_EQ(whole["model_times_from_s"].get<double>(), 0.0);
  EXPECT_EQ(whole["ranks"]["seconds_from_s"].get<double>(), 0.0);
  const fs::path d = copy_of_reference("models_carried");
  fs::remove(ckpt(d, 60));
  std::vector<std::string> names;
  double wall_before = 0.0, resumed_at_s = 0.0;
  {
    io::CheckpointReader r(ckpt(d, 40));
    names = r.strings("run.model_names");
    wall_before = r.scalar("run.wall_time_s");
    resumed_at_s = r.scalar("run.time_s");
    EXPECT_EQ(r.scalar("run.model_times_from_s"), 0.0);
  }
  ASSERT_NE(std::find(names.begin(), names.end(), "fluid"), names.end());
  const double carried = 1e6;
  const std::vector<double> planted(names.size(), carried);
  ASSERT_TRUE(overwrite_sealed(ckpt(d, 40), "run.model_wall_time_s", planted));
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(difference(reference(), d), "");
  const auto s = nlohmann::json::parse(slurp(d / "summary.json"));
  EXPECT_EQ(s["model_times_from_s"].get<double>(), 0.0);
  EXPECT_EQ(s["ranks"]["seconds_from_s"].get<double>(), resumed_at_s);
  const double attempt_wall_s = s["wall_time_s"].get<double>() - wall_before;
  for (const auto& name : names) {
    ASSERT_TRUE(s["models"].contains(name)) << name;
    const double total = s["models"][name]["wall_time_s"].get<double>();
    EXPECT_GE(total, carried) << name;
    EXPECT_LE(total, carried + attempt_wall_s) << name;
  }
}

// Checkpoints of builds before runs carried their models' wall times: the run resumes bit for
// bit, and its summary says from when its `models` count (the resume point), instead of
// presenting the last attempt's times as the whole run's.
TEST_F(CheckpointFaults, CheckpointWithoutModelTimesCountsThemFromTheResumePoint) {
  const fs::path d = copy_of_reference("no_model_times");
  fs::remove(ckpt(d, 60));
  const double resumed_at_s = io::CheckpointReader(ckpt(d, 40)).scalar("run.time_s");
  const hid_t f = open_for_edit(ckpt(d, 40));
  ASSERT_GE(f, 0);
  ASSERT_GE(H5Adelete(f, "sha256_footer"), 0);
  for (const char* name : {"run.model_names", "run.model_wall_time_s", "run.model_times_from_s"})
    ASSERT_GE(H5Ldelete(f, name, H5P_DEFAULT), 0) << name;
  H5Fclose(f);
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(difference(reference(), d), "");
  const auto s = nlohmann::json::parse(slurp(d / "summary.json"));
  EXPECT_EQ(s["model_times_from_s"].get<double>(), resumed_at_s);
  EXPECT_GT(resumed_at_s, 0.0);
  // Its next checkpoint (the end's) says so too, for the attempts after it.
  EXPECT_EQ(io::CheckpointReader(ckpt(d, 60)).scalar("run.model_times_from_s"), resumed_at_s);
}

TEST_F(CheckpointFaults, StateFailingValidationIsRefusedNamingTheCheckAndTheOlderOneIsUsed) {
  // A negative particle id written on purpose, the file sealed again: its hash is right.
  const auto poison = [](const fs::path& file) {
    const hid_t f = open_for_edit(file);
    ASSERT_GE(f, 0);
    const hid_t ds = H5Dopen2(f, "dem.id", H5P_DEFAULT);
    std::vector<std::int64_t> ids(static_cast<std::size_t>(H5Sget_simple_extent_npoints(H5Dget_space(ds))));
    H5Dread(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids.data());
    ids[7] = -5;
    H5Dwrite(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids.data());
    H5Dclose(ds);
    H5Fclose(f);
    io::seal_file(file);
    EXPECT_EQ(io::verify_file(file), io::Integrity::kVerified);
  };
  const fs::path d = copy_of_reference("invalid");
  poison(ckpt(d, 60));
  const CaseRun r = run_case(d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.err.find("dataset 'dem.id' fails the check: particle id -5 at index 7 is negative"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::exists(ckpt(d, 60).string() + ".bad"));
  EXPECT_EQ(difference(reference(), d), "") << "resumed from t = 0.04";

  // The only checkpoint: exit 4 naming the check, the file left where it is.
  const fs::path lone = copy_of_reference("invalid_lone");
  fs::remove(ckpt(lone, 20));
  fs::remove(ckpt(lone, 40));
  poison(ckpt(lone, 60));
  const std::string bytes = slurp(ckpt(lone, 60));
  const CaseRun r4 = run_case(lone);
  EXPECT_EQ(r4.rc, boycott::kExitCheckpointError) << r4.err;
  EXPECT_NE(r4.err.find("'dem.id' fails the check"), std::string::npos) << r4.err;
  EXPECT_EQ(slurp(ckpt(lone, 60)), bytes);
}

TEST_F(CheckpointFaults, FullDiskExits74KeepsTheLastCheckpointAndResumesBitwiseOnceSpaceIsBack) {
  const fs::path mnt = root_ / "small_disk";
  fs::create_directories(mnt);
  // 2 MB: room for the first checkpoint (1.3 MB), not the second.
  if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=2m") != 0)
    GTEST_SKIP() << "cannot mount a 2 MB tmpfs here (" << std::strerror(errno) << "): needs root";
  const fs::path d = mnt / "run";
  const CaseRun full = run_case(d);
  EXPECT_EQ(full.rc, boycott::kExitStorageError) << full.err;
  EXPECT_NE(full.err.find("No space left on device"), std::string::npos) << full.err;
  EXPECT_EQ(full.err.find("MPI_FINALIZE"), std::string::npos) << full.err;
  const auto left = io::checkpoints_newest_first(d);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0], ckpt(d, 20));
  EXPECT_EQ(io::verify_file(left[0]), io::Integrity::kVerified);
  for (const auto& e : fs::recursive_directory_iterator(d))
    EXPECT_NE(e.path().extension(), ".tmp") << "partial file left: " << e.path();
  EXPECT_FALSE(fs::exists(d / "summary.json"));
  // Space is back: the same command resumes and ends where the uninterrupted run ends.
  ASSERT_EQ(::mount("tmpfs", mnt.c_str(), "tmpfs", MS_REMOUNT, "size=16m"), 0) << std::strerror(errno);
  const CaseRun again = run_case(d);
  EXPECT_EQ(again.rc, 0) << again.err;
  EXPECT_EQ(difference(reference(), d), "");
  if (::umount(mnt.c_str()) != 0) ::umount2(mnt.c_str(), MNT_DETACH);
}

}  // namespace
