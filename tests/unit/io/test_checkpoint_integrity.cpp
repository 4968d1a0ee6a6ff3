// Checkpoint files that prove they are intact: SHA-256 against the standard's examples, a file
// sealed by the project's own SHA-256 before nettle computed it still verified, every flipped byte of a
// sealed file refused, files without a hash accepted as unverified, states that no run can continue from
// refused naming the check, and a write to a full disk reported as a storage error with the system's words,
// the .tmp removed.
#include <fcntl.h>
#include <hdf5.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/checkpoint_file.hpp"
#include "io/sha256.hpp"
#include "io/state_checks.hpp"

namespace boycott::io {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/boycott_ckpt_unit_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void spill(const fs::path& f, const std::string& bytes) {
  std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes;
}

std::string sha(const std::string& s) {
  Sha256 h;
  h.update(s.data(), s.size());
  return h.hex();
}

// FIPS 180-2 appendix B (and the NIST example values for the empty string).
TEST(Sha256, MatchesTheStandardsExamples) {
  EXPECT_EQ(sha("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // One million 'a', fed in uneven pieces (the buffering across update() calls).
  Sha256 h;
  const std::string chunk(997, 'a');
  std::size_t left = 1000000;
  while (left > 0) {
    const std::size_t n = std::min(left, chunk.size());
    h.update(chunk.data(), n);
    left -= n;
  }
  EXPECT_EQ(h.hex(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

void write_small_checkpoint(const fs::path& path) {
  CheckpointWriter w(path);
  w.put_string("case_id", "0123456789abcdef");
  std::vector<double> x(200);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.001 * static_cast<double>(i);
  w.put("dem.array00", x);
  w.put("run.time_s", 0.25);
  w.put_int("run.steps", 250);
  w.commit();
}

TEST(CheckpointFile, SealedFileVerifiesAndEveryFlippedByteIsRefused) {
  TempDir d;
  const fs::path f = d.path / "ckpt_000000000250.h5";
  write_small_checkpoint(f);
  EXPECT_FALSE(fs::exists(f.string() + ".tmp"));
  {
    CheckpointReader r(f);
    EXPECT_EQ(r.integrity(), Integrity::kVerified);
    EXPECT_EQ(r.scalar("run.time_s"), 0.25);
  }
  const std::string good = slurp(f);
  // Every byte of the first and last 256 (superblock, root group, the footer), every fourth
  // byte between.
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < good.size(); ++i)
    if (i < 256 || i + 256 >= good.size() || i % 4 == 0) offsets.push_back(i);
  int refused = 0;
  for (const std::size_t i : offsets) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x10);
    spill(f, bad);
    try {
      CheckpointReader r(f);
      ADD_FAILURE() << "a flip at byte " << i << " of " << good.size() << " was accepted";
    } catch (const CheckpointError&) {
      ++refused;
    }
  }
  EXPECT_EQ(refused, static_cast<int>(offsets.size()));
  std::printf("[ report ] %d of %zu single-byte flips refused (a %zu-byte file)\n", refused, offsets.size(),
              good.size());
}

// tests/data/ckpt_sealed_own_sha256.h5: write_small_checkpoint's file as the build before nettle
// wrote it, sealed by the SHA-256 the project then computed itself (written from FIPS 180-4):
// the checkpoints of runs made before the change still verify.
TEST(CheckpointFile, FileSealedByTheEarlierOwnSha256StillVerifies) {
  TempDir d;
  const fs::path f = d.path / "ckpt_000000000250.h5";
  fs::copy_file(fs::path(BOYCOTT_SOURCE_DIR) / "tests/data/ckpt_sealed_own_sha256.h5", f);
  EXPECT_EQ(verify_file(f), Integrity::kVerified);
  CheckpointReader r(f);
  EXPECT_EQ(r.integrity(), Integrity::kVerified);
  EXPECT_EQ(r.scalar("run.time_s"), 0.25);
}

TEST(CheckpointFile, LostHashFooterIsRefused) {
  TempDir d;
  const fs::path f = d.path / "ckpt_000000000250.h5";
  write_small_checkpoint(f);
  fs::resize_file(f, fs::file_size(f) - 81);  // the footer cut off: HDF5 alone would open it
  try {
    CheckpointReader r(f);
    FAIL() << "a file that lost its hash was accepted";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("lost"), std::string::npos) << e.what();
  }
}

TEST(CheckpointFile, FileWrittenBeforeHashesOpensUnverified) {
  TempDir d;
  const fs::path f = d.path / "ckpt_000000000250.h5";
  // As the writer of earlier builds left it: datasets and the `complete` attribute, no footer.
  const hid_t file = H5Fcreate(f.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hsize_t n = 1;
  const double t = 0.5;
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t ds =
      H5Dcreate2(file, "run.time_s", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &t);
  H5Dclose(ds);
  H5Sclose(space);
  const hid_t scalar = H5Screate(H5S_SCALAR);
  const hid_t at = H5Acreate2(file, "complete", H5T_NATIVE_INT, scalar, H5P_DEFAULT, H5P_DEFAULT);
  const int one = 1;
  H5Awrite(at, H5T_NATIVE_INT, &one);
  H5Aclose(at);
  H5Sclose(scalar);
  H5Fclose(file);
  CheckpointReader r(f);
  EXPECT_EQ(r.integrity(), Integrity::kUnverified);
  EXPECT_EQ(r.scalar("run.time_s"), 0.5);
}

TEST(CheckpointFile, SetAsideKeepsTheFileUnderANewName) {
  TempDir d;
  const fs::path f = d.path / "checkpoints" / "ckpt_000000000250.h5";
  write_small_checkpoint(f);
  const std::string bytes = slurp(f);
  const fs::path kept = set_aside(f);
  EXPECT_EQ(kept.filename().string(), "ckpt_000000000250.h5.bad");
  EXPECT_EQ(slurp(kept), bytes);
  EXPECT_TRUE(checkpoints_newest_first(d.path).empty()) << "a set-aside file is no checkpoint any more";
  write_small_checkpoint(f);
  EXPECT_EQ(set_aside(f).filename().string(), "ckpt_000000000250.h5.bad2");
}

particles::DemState good_dem(std::size_t n) {
  particles::DemState s;
  for (std::size_t i = 0; i < n; ++i)
    s.store.add(static_cast<std::int64_t>(i), 0.001 + 0.002 * static_cast<double>(i), 0.003, 0.005, 3e-4,
                2650.0);
  s.time_s = 0.1;
  return s;
}

const StateBounds kBox{{0.02, 0.006, 0.02}, {true, false, true}};

void expect_refused(const std::function<void()>& check, const std::string& dataset,
                    const std::string& words) {
  try {
    check();
    ADD_FAILURE() << "accepted; expected a refusal naming " << dataset;
  } catch (const CheckpointError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'" + dataset + "'"), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << what;
  }
}

TEST(StateChecks, AGoodStateAndPeriodicCoordinatesBetweenWrapsPass) {
  auto s = good_dem(5);
  s.store.x[0] = -0.015;  // periodic: less than one box length outside
  s.store.z[1] = 0.039;
  EXPECT_NO_THROW(check_state(s, kBox, "f.h5", "dem."));
}

TEST(StateChecks, BadParticleStatesAreRefusedNamingTheDatasetAndTheCheck) {
  auto s = good_dem(5);
  s.store.id[2] = -5;
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.id", "negative");
  s = good_dem(5);
  s.store.id[3] = 1;
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.id", "unique");
  s = good_dem(5);
  s.store.vz[4] = std::numeric_limits<double>::quiet_NaN();
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.array05", "not finite");
  s = good_dem(5);
  s.store.y[0] = 0.0075;  // walled: beyond the wall by more than a radius
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.array01", "outside the box");
  s = good_dem(5);
  s.store.x[0] = 0.045;  // periodic: more than one box length outside
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.array00", "outside the box");
  s = good_dem(5);
  s.pair_id_a = {-1};
  s.pair_id_b = {2};
  expect_refused([&] { check_state(s, kBox, "f.h5", "dem."); }, "dem.pair_id_a", "negative");
}

TEST(StateChecks, FluidFractionOutsideZeroOneAndNonFiniteFieldsAreRefused) {
  fluid::FluidState f;
  f.fields.assign(11, std::vector<double>(8, 0.5));
  EXPECT_NO_THROW(check_state(f, "f.h5", "fluid."));
  f.fields[8][3] = 0.0;
  expect_refused([&] { check_state(f, "f.h5", "fluid."); }, "fluid.field.08", "outside (0, 1]");
  f.fields[8][3] = 1.0 + 1e-9;
  expect_refused([&] { check_state(f, "f.h5", "fluid."); }, "fluid.field.08", "outside (0, 1]");
  f.fields[8][3] = 1.0;
  f.fields[6][0] = std::numeric_limits<double>::infinity();
  expect_refused([&] { check_state(f, "f.h5", "fluid."); }, "fluid.field.06", "not finite");
}

/// A small tmpfs at dir, or a reason why not (mount needs root).
std::string mount_tmpfs(const fs::path& dir, const char* size) {
  fs::create_directories(dir);
  if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, (std::string("size=") + size).c_str()) != 0)
    return std::strerror(errno);
  return "";
}

TEST(CheckpointStorage, WriteToAFullDiskIsAStorageErrorWithTheSystemsWordsAndLeavesNoTmp) {
  TempDir d;
  const fs::path mnt = d.path / "small";
  const std::string why = mount_tmpfs(mnt, "256k");
  if (!why.empty()) GTEST_SKIP() << "cannot mount a small tmpfs here (" << why << "): needs root";
  const fs::path good = mnt / "checkpoints" / "ckpt_000000000001.h5";
  write_small_checkpoint(good);
  const std::string before = slurp(good);
  const fs::path big = mnt / "checkpoints" / "ckpt_000000000002.h5";
  try {
    CheckpointWriter w(big);
    w.put("dem.array00", std::vector<double>(100000, 1.0));  // 800 kB into 256 kB
    w.commit();
    ADD_FAILURE() << "a write to a full disk succeeded";
  } catch (const StorageError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a StorageError: " << e.what();
  }
  EXPECT_FALSE(fs::exists(big));
  EXPECT_FALSE(fs::exists(big.string() + ".tmp")) << "the partial .tmp is removed";
  EXPECT_EQ(slurp(good), before);
  EXPECT_EQ(CheckpointReader(good).integrity(), Integrity::kVerified);
  ::umount(mnt.c_str());
}

}  // namespace
}  // namespace boycott::io
