#include "io/checkpoint_file.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <regex>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kComplete = "complete";

void check(herr_t e, const std::string& what) {
  if (e < 0) throw CheckpointError(fmt::format("HDF5 error: {}", what));
}

/// Silences HDF5's own error stack printing; we report errors ourselves.
struct QuietHdf5 {
  QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const QuietHdf5 kQuiet;

template <class T>
void write_dataset(hid_t file, const std::string& name, hid_t type, const std::vector<T>& v) {
  const hsize_t n = v.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t ds = H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (ds < 0) {
    H5Sclose(space);
    throw CheckpointError(fmt::format("cannot create dataset '{}'", name));
  }
  if (n > 0) check(H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "write " + name);
  H5Dclose(ds);
  H5Sclose(space);
}

template <class T>
std::vector<T> read_dataset(hid_t file, const fs::path& path, const std::string& name, hid_t type) {
  const hid_t ds = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  if (ds < 0) throw CheckpointError(fmt::format("{}: dataset '{}' is missing", path.string(), name));
  const hid_t space = H5Dget_space(ds);
  // Any rank: all points, slowest dimension first.
  const hssize_t npts = H5Sget_simple_extent_npoints(space);
  const auto n = static_cast<std::size_t>(npts < 0 ? 0 : npts);
  std::vector<T> v(n);
  herr_t e = n > 0 ? H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) : 0;
  H5Sclose(space);
  H5Dclose(ds);
  if (e < 0)
    throw CheckpointError(fmt::format("{}: dataset '{}' is unreadable (corrupt file?)", path.string(), name));
  return v;
}

}  // namespace

CheckpointWriter::CheckpointWriter(fs::path final_path) : final_(std::move(final_path)) {
  tmp_ = final_;
  tmp_ += ".tmp";
  fs::create_directories(final_.parent_path());
  file_ = H5Fcreate(tmp_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw CheckpointError(fmt::format("cannot create {}", tmp_.string()));
}

CheckpointWriter::~CheckpointWriter() {
  if (file_ >= 0) H5Fclose(file_);
  if (!committed_) {
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void CheckpointWriter::put(const std::string& name, const std::vector<double>& v) {
  write_dataset(file_, name, H5T_NATIVE_DOUBLE, v);
}
void CheckpointWriter::put(const std::string& name, const std::vector<std::int64_t>& v) {
  write_dataset(file_, name, H5T_NATIVE_INT64, v);
}
void CheckpointWriter::put_string(const std::string& name, const std::string& s) {
  std::vector<std::int64_t> bytes(s.begin(), s.end());
  put(name, bytes);
}

void CheckpointWriter::put_3d(const std::string& name, const std::array<std::size_t, 3>& dims,
                              const std::vector<double>& v) {
  const hsize_t d[3] = {dims[0], dims[1], dims[2]};
  if (d[0] * d[1] * d[2] != v.size()) throw CheckpointError(fmt::format("dataset '{}': size mismatch", name));
  const hid_t space = H5Screate_simple(3, d, nullptr);
  const hid_t ds =
      H5Dcreate2(file_, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (ds < 0) {
    H5Sclose(space);
    throw CheckpointError(fmt::format("cannot create dataset '{}'", name));
  }
  check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "write " + name);
  H5Dclose(ds);
  H5Sclose(space);
}

void CheckpointWriter::put_group(const std::string& name) {
  const hid_t g = H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) throw CheckpointError(fmt::format("cannot create group '{}'", name));
  H5Gclose(g);
}

void CheckpointWriter::commit() {
  // The marker goes in last: a file without it was cut short.
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t at = H5Acreate2(file_, kComplete, H5T_NATIVE_INT, space, H5P_DEFAULT, H5P_DEFAULT);
  const int one = 1;
  check(H5Awrite(at, H5T_NATIVE_INT, &one), "write completeness marker");
  H5Aclose(at);
  H5Sclose(space);
  check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "flush " + tmp_.string());
  H5Fclose(file_);
  file_ = -1;
  const int fd = ::open(tmp_.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  fs::rename(tmp_, final_);
  const int dfd = ::open(final_.parent_path().c_str(), O_RDONLY);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  committed_ = true;
}

CheckpointReader::CheckpointReader(fs::path path) : path_(std::move(path)) {
  file_ = H5Fopen(path_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0)
    throw CheckpointError(
        fmt::format("checkpoint {} cannot be opened as HDF5 (truncated or corrupt); it is left "
                    "in place: move it away to start over",
                    path_.string()));
  if (H5Aexists(file_, kComplete) <= 0)
    throw CheckpointError(
        fmt::format("checkpoint {} has no completeness marker (cut short while written); it is "
                    "left in place: move it away to start over",
                    path_.string()));
}

CheckpointReader::~CheckpointReader() {
  if (file_ >= 0) H5Fclose(file_);
}

bool CheckpointReader::has(const std::string& name) const {
  return H5Lexists(file_, name.c_str(), H5P_DEFAULT) > 0;
}
std::vector<double> CheckpointReader::doubles(const std::string& name) const {
  return read_dataset<double>(file_, path_, name, H5T_NATIVE_DOUBLE);
}
std::vector<std::int64_t> CheckpointReader::int64s(const std::string& name) const {
  return read_dataset<std::int64_t>(file_, path_, name, H5T_NATIVE_INT64);
}
double CheckpointReader::scalar(const std::string& name) const {
  const auto v = doubles(name);
  if (v.size() != 1) throw CheckpointError(fmt::format("{}: '{}' is not a scalar", path_.string(), name));
  return v[0];
}
std::int64_t CheckpointReader::integer(const std::string& name) const {
  const auto v = int64s(name);
  if (v.size() != 1) throw CheckpointError(fmt::format("{}: '{}' is not a scalar", path_.string(), name));
  return v[0];
}
std::string CheckpointReader::string(const std::string& name) const {
  const auto v = int64s(name);
  return std::string(v.begin(), v.end());
}

fs::path checkpoint_path(const fs::path& run_dir, std::int64_t step) {
  return run_dir / "checkpoints" / fmt::format("ckpt_{:012d}.h5", step);
}

namespace {
std::vector<std::pair<std::int64_t, fs::path>> list_checkpoints(const fs::path& run_dir) {
  std::vector<std::pair<std::int64_t, fs::path>> out;
  const fs::path d = run_dir / "checkpoints";
  if (!fs::exists(d)) return out;
  static const std::regex re(R"(ckpt_(\d+)\.h5)");
  for (const auto& e : fs::directory_iterator(d)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, m, re)) out.emplace_back(std::stoll(m[1]), e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

std::optional<fs::path> latest_checkpoint(const fs::path& run_dir) {
  const auto all = list_checkpoints(run_dir);
  if (all.empty()) return std::nullopt;
  return all.back().second;
}

void prune_checkpoints(const fs::path& run_dir, int keep) {
  auto all = list_checkpoints(run_dir);
  const int n = static_cast<int>(all.size());
  for (int i = 0; i + keep < n; ++i) fs::remove(all[i].second);
}

}  // namespace boycott::io
