#pragma once
// Restart checkpoints as HDF5 files of named datasets (README.md, "Running a case").
//
// One file per checkpoint, DIR/checkpoints/ckpt_<step>.h5. A writer builds the file in memory,
// writes the attribute `complete` last, then writes the image to "<name>.h5.tmp" followed by the
// SHA-256 of every byte of it (a footer after HDF5's end of file, which HDF5 ignores), fsyncs and
// renames: a kill during a write leaves only a stray .tmp and the previous checkpoint intact,
// and a file in place is one whose hash was written with it. A reader checks the hash before HDF5 opens the
// file, so damage to the data and to HDF5's own metadata are both refused (CheckpointError naming the file);
// files written before checkpoints carried a hash open as unverified. Nothing is ever deleted or
// overwritten on such an error. A failed write is a StorageError (disk full, I/O error) with the
// system's own words; the .tmp is removed.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace boycott::io {

class CheckpointWriter {
 public:
  /// Starts `final_path` (in memory; written as final_path + ".tmp" and renamed by commit).
  explicit CheckpointWriter(std::filesystem::path final_path);
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  void put(const std::string& name, const std::vector<double>& v);
  void put(const std::string& name, const std::vector<std::int64_t>& v);
  void put(const std::string& name, double v) { put(name, std::vector<double>{v}); }
  void put_int(const std::string& name, std::int64_t v) { put(name, std::vector<std::int64_t>{v}); }
  /// A string as its character codes (int64): how checkpoints have always stored them.
  void put_string(const std::string& name, const std::string& s);
  /// A list of HDF5 strings (fixed length, null-terminated; h5dump and h5py show them as text).
  void put_strings(const std::string& name, const std::vector<std::string>& list);
  /// A 2-D array {rows, cols} stored row by row (N x 3 vectors: one row per point).
  void put_2d(const std::string& name, std::size_t rows, std::size_t cols, const std::vector<double>& v);
  /// A 3-D array stored slowest-first with dimensions {n0, n1, n2} (z, y, x for grid fields).
  void put_3d(const std::string& name, const std::array<std::size_t, 3>& dims, const std::vector<double>& v);
  /// Creates a group (for names "group/dataset").
  void put_group(const std::string& name);
  /// Marks the file complete, writes it with its hash, fsyncs and renames it into place.
  /// StorageError (the .tmp removed) when the storage fails.
  void commit();

 private:
  std::filesystem::path final_, tmp_;
  long long file_ = -1;
  bool committed_ = false;
};

/// What the hash footer of a checkpoint file says about it.
enum class Integrity {
  kVerified,    ///< its SHA-256 footer matches every byte before it
  kUnverified,  ///< no footer and no claim to one: written before checkpoints carried a hash
  kNotChecked,  ///< opened without checking (CheckpointReader::Verify::kNo)
};

/// Appends the SHA-256 footer of the file's bytes and fsyncs it; StorageError when that fails.
/// The writer's last step before the rename (public for tests that alter a file on purpose).
void seal_file(const std::filesystem::path& path);
/// Checks a file's footer: kVerified, kUnverified (none), or CheckpointError (a footer that does
/// not match the bytes before it, or an unreadable file), naming the file.
Integrity verify_file(const std::filesystem::path& path);

class CheckpointReader {
 public:
  enum class Verify { kYes, kNo };
  /// Checks the hash (with Verify::kYes), opens the file and checks the completeness marker;
  /// throws CheckpointError otherwise, also for a file written with a hash that has lost it.
  explicit CheckpointReader(std::filesystem::path path, Verify verify = Verify::kYes);
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;

  bool has(const std::string& name) const;
  std::vector<double> doubles(const std::string& name) const;
  std::vector<std::int64_t> int64s(const std::string& name) const;
  double scalar(const std::string& name) const;
  std::int64_t integer(const std::string& name) const;
  std::string string(const std::string& name) const;
  /// A list written by put_strings.
  std::vector<std::string> strings(const std::string& name) const;
  /// The dimensions of a dataset, slowest first (empty for a scalar).
  std::vector<std::size_t> dims(const std::string& name) const;
  const std::filesystem::path& path() const { return path_; }
  Integrity integrity() const { return integrity_; }

 private:
  std::filesystem::path path_;
  long long file_ = -1;
  Integrity integrity_ = Integrity::kNotChecked;
};

/// ckpt_<step, zero padded>.h5 in dir/checkpoints.
std::filesystem::path checkpoint_path(const std::filesystem::path& run_dir, std::int64_t step);
/// The newest checkpoint file of a run folder (by step), or none. Does not open it.
std::optional<std::filesystem::path> latest_checkpoint(const std::filesystem::path& run_dir);
/// The checkpoint files of a run folder, newest first. Does not open them.
std::vector<std::filesystem::path> checkpoints_newest_first(const std::filesystem::path& run_dir);
/// Renames a refused checkpoint to <name>.bad (or .bad2, ...), out of the way of later
/// checkpoints of the same step and of pruning; returns the new path. Never deletes it;
/// StorageError when the rename fails.
std::filesystem::path set_aside(const std::filesystem::path& checkpoint);
/// Deletes all but the newest `keep` checkpoints (only complete, older ones).
void prune_checkpoints(const std::filesystem::path& run_dir, int keep);

}  // namespace boycott::io
