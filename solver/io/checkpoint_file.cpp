#include "io/checkpoint_file.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <regex>
#include <string_view>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/sha256.hpp"

namespace boycott::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kComplete = "complete";
/// Set in every file written with a hash footer: a file that claims one but has none lost it.
constexpr const char* kSealed = "sha256_footer";
/// The footer: this text, 64 hex digits of the SHA-256 of every byte before the footer, "\n".
constexpr char kFooterMagic[] = "\nboycott-sha256 ";
constexpr std::size_t kMagicSize = sizeof kFooterMagic - 1;
constexpr std::size_t kFooterSize = kMagicSize + 64 + 1;

/// Silences HDF5's own error stack printing; we report errors ourselves.
struct QuietHdf5 {
  QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const QuietHdf5 kQuiet;

/// The cause HDF5 recorded for the call that just failed: the system's words when a read or
/// write failed, else HDF5's innermost message.
std::string hdf5_cause() {
  struct Found {
    std::string system, innermost;
  } found;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
        auto& f = *static_cast<Found*>(data);
        const std::string desc = e->desc ? e->desc : "";
        if (f.innermost.empty()) f.innermost = desc;
        const auto at = desc.find("error message = '");
        if (f.system.empty() && at != std::string::npos) {
          const auto from = at + 17, to = desc.find('\'', from);
          f.system = desc.substr(from, to == std::string::npos ? std::string::npos : to - from);
        }
        return 0;
      },
      &found);
  if (!found.system.empty()) return found.system;
  return found.innermost.empty() ? "no message" : found.innermost;
}

[[noreturn]] void storage_failure(const std::string& what, const std::string& cause) {
  throw StorageError(fmt::format("{}: {}", what, cause));
}

/// The file is built in memory (HDF5's core driver): a call that fails there is this program's
/// error (a name used twice, say) or memory's, never the disk's.
[[noreturn]] void hdf5_failure(const std::string& what) {
  throw std::runtime_error(fmt::format("HDF5: {}: {}", what, hdf5_cause()));
}

template <class T>
void write_dataset(hid_t file, const std::string& name, hid_t type, const std::vector<T>& v) {
  const hsize_t n = v.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t ds = H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (ds < 0) {
    H5Sclose(space);
    hdf5_failure(fmt::format("cannot create dataset '{}'", name));
  }
  const herr_t e = n > 0 ? H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) : 0;
  H5Dclose(ds);
  H5Sclose(space);
  if (e < 0) hdf5_failure(fmt::format("cannot write dataset '{}'", name));
}

void write_int_attribute(hid_t file, const char* name, int value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t at = H5Acreate2(file, name, H5T_NATIVE_INT, space, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t e = at < 0 ? -1 : H5Awrite(at, H5T_NATIVE_INT, &value);
  if (at >= 0) H5Aclose(at);
  H5Sclose(space);
  if (e < 0) hdf5_failure(fmt::format("cannot write attribute '{}'", name));
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

/// fsync of a file or folder; StorageError with the system's words when it fails.
void fsync_path(const fs::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags);
  if (fd < 0) storage_failure(fmt::format("cannot open {} to sync it", p.string()), std::strerror(errno));
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    storage_failure(fmt::format("cannot sync {}", p.string()), std::strerror(err));
  }
  ::close(fd);
}

/// Reads [offset, offset + n) of fd into buf; false on a short read or error.
bool read_exact(int fd, void* buf, std::size_t n, off_t offset) {
  auto* p = static_cast<char*>(buf);
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, offset);
    if (got <= 0) return false;
    p += got, n -= static_cast<std::size_t>(got), offset += got;
  }
  return true;
}

/// SHA-256 of the first `n` bytes of fd (hex); nothing when they cannot be read.
std::optional<std::string> hash_prefix(int fd, std::size_t n) {
  Sha256 h;
  std::vector<char> buf(std::size_t{1} << 20);
  off_t offset = 0;
  while (n > 0) {
    const std::size_t chunk = std::min(n, buf.size());
    if (!read_exact(fd, buf.data(), chunk, offset)) return std::nullopt;
    h.update(buf.data(), chunk);
    n -= chunk;
    offset += static_cast<off_t>(chunk);
  }
  return h.hex();
}

bool is_hex64(const char* p) {
  return std::all_of(p, p + 64, [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

}  // namespace

void seal_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDWR);
  if (fd < 0) storage_failure(fmt::format("cannot open {} to seal it", path.string()), std::strerror(errno));
  struct stat sb {};
  std::string footer;
  int err = 0;
  if (::fstat(fd, &sb) != 0) {
    err = errno;
  } else if (const auto hex = hash_prefix(fd, static_cast<std::size_t>(sb.st_size))) {
    footer = std::string(kFooterMagic, kMagicSize) + *hex + "\n";
    std::size_t off = 0;
    while (off < footer.size() && err == 0) {
      const ssize_t n =
          ::pwrite(fd, footer.data() + off, footer.size() - off, sb.st_size + static_cast<off_t>(off));
      if (n <= 0)
        err = n < 0 ? errno : ENOSPC;
      else
        off += static_cast<std::size_t>(n);
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
  } else {
    err = errno != 0 ? errno : EIO;
  }
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0)
    storage_failure(fmt::format("cannot write the hash of {}", path.string()), std::strerror(err));
}

Integrity verify_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0)
    throw CheckpointError(
        fmt::format("checkpoint {} cannot be read: {}", path.string(), std::strerror(errno)));
  struct stat sb {};
  char footer[kFooterSize];
  const bool has_footer = ::fstat(fd, &sb) == 0 && static_cast<std::size_t>(sb.st_size) >= kFooterSize &&
                          read_exact(fd, footer, kFooterSize, sb.st_size - static_cast<off_t>(kFooterSize)) &&
                          std::memcmp(footer, kFooterMagic, kMagicSize) == 0 &&
                          is_hex64(footer + kMagicSize) && footer[kFooterSize - 1] == '\n';
  if (!has_footer) {
    ::close(fd);
    return Integrity::kUnverified;
  }
  const auto hex = hash_prefix(fd, static_cast<std::size_t>(sb.st_size) - kFooterSize);
  ::close(fd);
  if (!hex)
    throw CheckpointError(fmt::format("checkpoint {} cannot be read to check its hash", path.string()));
  if (std::memcmp(hex->data(), footer + kMagicSize, 64) != 0)
    throw CheckpointError(fmt::format(
        "checkpoint {} does not match its SHA-256 (damaged since it was written: sha256 {}, recorded {})",
        path.string(), hex->substr(0, 16), std::string(footer + kMagicSize, 16)));
  return Integrity::kVerified;
}

CheckpointWriter::CheckpointWriter(fs::path final_path) : final_(std::move(final_path)) {
  tmp_ = final_;
  tmp_ += ".tmp";
  // Built in memory, written to disk in one piece by commit(): every failure of the storage is
  // then a failed write() of ours, with the system's words, and HDF5 never holds a half-written
  // file open.
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_fapl_core(fapl, std::size_t{1} << 20, 0);
  file_ = H5Fcreate(tmp_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  if (file_ < 0) hdf5_failure(fmt::format("cannot create {} in memory", tmp_.string()));
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

void CheckpointWriter::put_strings(const std::string& name, const std::vector<std::string>& list) {
  std::size_t len = 1;
  for (const auto& x : list) len = std::max(len, x.size() + 1);
  std::vector<char> buf(len * list.size(), '\0');
  for (std::size_t i = 0; i < list.size(); ++i)
    std::copy(list[i].begin(), list[i].end(), buf.begin() + i * len);
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, len);
  H5Tset_strpad(type, H5T_STR_NULLTERM);
  const hsize_t n = list.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t ds = H5Dcreate2(file_, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t e = ds < 0 ? -1 : n > 0 ? H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) : 0;
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(space);
  H5Tclose(type);
  if (e < 0) hdf5_failure(fmt::format("cannot write string list '{}'", name));
}

void CheckpointWriter::put_2d(const std::string& name, std::size_t rows, std::size_t cols,
                              const std::vector<double>& v) {
  const hsize_t d[2] = {rows, cols};
  if (d[0] * d[1] != v.size())
    throw std::logic_error(
        fmt::format("dataset '{}': {} values for dimensions {}x{}", name, v.size(), d[0], d[1]));
  const hid_t space = H5Screate_simple(2, d, nullptr);
  const hid_t ds =
      H5Dcreate2(file_, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t e = ds < 0      ? -1
                   : v.empty() ? 0
                               : H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(space);
  if (e < 0) hdf5_failure(fmt::format("cannot write dataset '{}'", name));
}

void CheckpointWriter::put_3d(const std::string& name, const std::array<std::size_t, 3>& dims,
                              const std::vector<double>& v) {
  const hsize_t d[3] = {dims[0], dims[1], dims[2]};
  if (d[0] * d[1] * d[2] != v.size())
    throw std::logic_error(
        fmt::format("dataset '{}': {} values for dimensions {}x{}x{}", name, v.size(), d[0], d[1], d[2]));
  const hid_t space = H5Screate_simple(3, d, nullptr);
  const hid_t ds =
      H5Dcreate2(file_, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (ds < 0) {
    H5Sclose(space);
    hdf5_failure(fmt::format("cannot create dataset '{}'", name));
  }
  const herr_t e = H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Dclose(ds);
  H5Sclose(space);
  if (e < 0) hdf5_failure(fmt::format("cannot write dataset '{}'", name));
}

void CheckpointWriter::put_group(const std::string& name) {
  const hid_t g = H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) hdf5_failure(fmt::format("cannot create group '{}'", name));
  H5Gclose(g);
}

void CheckpointWriter::commit() {
  // The marker goes in last: a file without it was cut short.
  write_int_attribute(file_, kSealed, 1);
  write_int_attribute(file_, kComplete, 1);
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) hdf5_failure("cannot flush the file image");
  const ssize_t size = H5Fget_file_image(file_, nullptr, 0);
  std::vector<char> image(size > 0 ? static_cast<std::size_t>(size) : 0);
  if (size <= 0 || H5Fget_file_image(file_, image.data(), image.size()) != size)
    hdf5_failure("cannot take the file image");
  H5Fclose(file_);
  file_ = -1;
  // The hash covers every byte of the image (data and HDF5's own metadata). Then write, fsync,
  // rename and fsync the folder: once the name is there, so are the bytes and the hash that
  // proves them; a failure before leaves no .tmp and the previous checkpoints as they were.
  Sha256 h;
  h.update(image.data(), image.size());
  const std::string footer = std::string(kFooterMagic, kMagicSize) + h.hex() + "\n";
  std::error_code ec;
  fs::create_directories(final_.parent_path(), ec);
  if (ec) storage_failure(fmt::format("cannot create {}", final_.parent_path().string()), ec.message());
  write_file_atomic(final_, {std::string_view(image.data(), image.size()), std::string_view(footer)});
  committed_ = true;
  fsync_path(final_.parent_path(), O_RDONLY | O_DIRECTORY);
}

CheckpointReader::CheckpointReader(fs::path path, Verify verify) : path_(std::move(path)) {
  if (verify == Verify::kYes) integrity_ = verify_file(path_);
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
  if (integrity_ == Integrity::kUnverified && H5Aexists(file_, kSealed) != 0)
    throw CheckpointError(
        fmt::format("checkpoint {} was written with a SHA-256 footer and has lost it (cut short or altered)",
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
std::vector<std::string> CheckpointReader::strings(const std::string& name) const {
  const hid_t ds = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
  if (ds < 0) throw CheckpointError(fmt::format("{}: dataset '{}' is missing", path_.string(), name));
  const hid_t type = H5Dget_type(ds), space = H5Dget_space(ds);
  const hssize_t npts = H5Sget_simple_extent_npoints(space);
  const std::size_t n = npts < 0 ? 0 : static_cast<std::size_t>(npts);
  const bool ok = H5Tget_class(type) == H5T_STRING && H5Tis_variable_str(type) == 0;
  const std::size_t len = ok ? H5Tget_size(type) : 0;
  std::vector<char> buf(len * n + 1, '\0');
  const herr_t e = !ok ? -1 : n > 0 ? H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) : 0;
  H5Sclose(space);
  H5Tclose(type);
  H5Dclose(ds);
  if (e < 0)
    throw CheckpointError(
        fmt::format("{}: dataset '{}' is not a list of fixed-length strings", path_.string(), name));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n; ++i) {
    const char* p = buf.data() + i * len;
    out.emplace_back(p, std::find(p, p + len, '\0'));
  }
  return out;
}
std::vector<std::size_t> CheckpointReader::dims(const std::string& name) const {
  const hid_t ds = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
  if (ds < 0) throw CheckpointError(fmt::format("{}: dataset '{}' is missing", path_.string(), name));
  const hid_t space = H5Dget_space(ds);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> d(rank > 0 ? static_cast<std::size_t>(rank) : 0);
  if (rank > 0) H5Sget_simple_extent_dims(space, d.data(), nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return std::vector<std::size_t>(d.begin(), d.end());
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

std::vector<fs::path> checkpoints_newest_first(const fs::path& run_dir) {
  std::vector<fs::path> out;
  const auto all = list_checkpoints(run_dir);
  for (auto it = all.rbegin(); it != all.rend(); ++it) out.push_back(it->second);
  return out;
}

fs::path set_aside(const fs::path& checkpoint) {
  for (int k = 1;; ++k) {
    const fs::path to = checkpoint.string() + (k == 1 ? ".bad" : fmt::format(".bad{}", k));
    if (fs::exists(to)) continue;
    std::error_code ec;
    fs::rename(checkpoint, to, ec);
    if (ec) storage_failure(fmt::format("cannot set {} aside", checkpoint.string()), ec.message());
    return to;
  }
}

void prune_checkpoints(const fs::path& run_dir, int keep) {
  auto all = list_checkpoints(run_dir);
  const int n = static_cast<int>(all.size());
  for (int i = 0; i + keep < n; ++i) fs::remove(all[i].second);
}

}  // namespace boycott::io
