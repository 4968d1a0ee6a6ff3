#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott::io {

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes) {
  write_file_atomic(path, {bytes});
}

void write_file_atomic(const std::filesystem::path& path, std::initializer_list<std::string_view> parts) {
  const std::string tmp = path.string() + ".tmp";
  const auto fail = [&](const char* what, int err) {
    ::unlink(tmp.c_str());
    throw StorageError(fmt::format("cannot {} {}: {}", what, tmp, std::strerror(err)));
  };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw StorageError(fmt::format("cannot create {}: {}", tmp, std::strerror(errno)));
  for (const std::string_view bytes : parts) {
    std::size_t off = 0;
    while (off < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + off, bytes.size() - off);
      if (n <= 0) {
        const int err = n < 0 ? errno : ENOSPC;
        ::close(fd);
        fail("write", err);
      }
      off += static_cast<std::size_t>(n);
    }
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    fail("sync", err);
  }
  if (::close(fd) != 0) fail("close", errno);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail("rename", ec.value());
}

}  // namespace boycott::io
