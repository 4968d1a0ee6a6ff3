#pragma once
// Restart checkpoints as HDF5 files of named datasets (design brief section 7, issue 5).
//
// One file per checkpoint, DIR/checkpoints/ckpt_<step>.h5. A writer fills "<name>.h5.tmp",
// writes the attribute `complete` last, flushes, fsyncs and renames: a kill during a write leaves
// only a stray .tmp and the previous checkpoint intact. A reader refuses a file without the
// marker (truncated or half written) and one whose case hash differs, with a CheckpointError
// naming the file; nothing is ever deleted or overwritten on such an error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace boycott::io {

class CheckpointWriter {
 public:
  /// Starts `final_path` (written as final_path + ".tmp" until commit).
  explicit CheckpointWriter(std::filesystem::path final_path);
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  void put(const std::string& name, const std::vector<double>& v);
  void put(const std::string& name, const std::vector<std::int64_t>& v);
  void put(const std::string& name, double v) { put(name, std::vector<double>{v}); }
  void put_int(const std::string& name, std::int64_t v) { put(name, std::vector<std::int64_t>{v}); }
  void put_string(const std::string& name, const std::string& s);
  /// A 3-D array stored slowest-first with dimensions {n0, n1, n2} (z, y, x for grid fields).
  void put_3d(const std::string& name, const std::array<std::size_t, 3>& dims, const std::vector<double>& v);
  /// Creates a group (for names "group/dataset").
  void put_group(const std::string& name);
  /// Marks the file complete, flushes, renames it into place.
  void commit();

 private:
  std::filesystem::path final_, tmp_;
  long long file_ = -1;
  bool committed_ = false;
};

class CheckpointReader {
 public:
  /// Opens and checks the completeness marker; throws CheckpointError otherwise.
  explicit CheckpointReader(std::filesystem::path path);
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;

  bool has(const std::string& name) const;
  std::vector<double> doubles(const std::string& name) const;
  std::vector<std::int64_t> int64s(const std::string& name) const;
  double scalar(const std::string& name) const;
  std::int64_t integer(const std::string& name) const;
  std::string string(const std::string& name) const;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  long long file_ = -1;
};

/// ckpt_<step, zero padded>.h5 in dir/checkpoints.
std::filesystem::path checkpoint_path(const std::filesystem::path& run_dir, std::int64_t step);
/// The newest checkpoint file of a run folder (by step), or none. Does not open it.
std::optional<std::filesystem::path> latest_checkpoint(const std::filesystem::path& run_dir);
/// Deletes all but the newest `keep` checkpoints (only complete, older ones).
void prune_checkpoints(const std::filesystem::path& run_dir, int keep);

}  // namespace boycott::io
