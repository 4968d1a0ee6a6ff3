#include "driver/run/run_folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace boycott::driver {

namespace fs = std::filesystem;

std::optional<int> lock_run_folder(const fs::path& dir) {
  const int fd = ::open((dir / ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot create '{}'", (dir / ".lock").string()));
  // Held by the solver as long as it lives: a solver orphaned by a killed driver is still
  // checkpointing, and a second driver must not start the case twice.
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return std::nullopt;
  }
  // The holder's pid, for the message of whoever finds the folder locked (a lock whose pid could
  // not be written still locks).
  const std::string pid = std::to_string(getpid()) + "\n";
  [[maybe_unused]] const bool named =
      ::ftruncate(fd, 0) == 0 && ::pwrite(fd, pid.data(), pid.size(), 0) == static_cast<ssize_t>(pid.size());
  return fd;
}

std::string run_folder_holder(const fs::path& dir) {
  std::ifstream in(dir / ".lock");
  std::string pid;
  in >> pid;
  return pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos ? "" : pid;
}

void unlock_run_folder(int lock_fd) {
  ::close(lock_fd);
}

bool run_folder_unheld(const fs::path& dir) {
  const int fd = ::open((dir / ".lock").c_str(), O_RDWR | O_CLOEXEC);
  const bool unheld = fd >= 0 && ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  if (fd >= 0) ::close(fd);
  return unheld;
}

}  // namespace boycott::driver
