#include "driver/run/slurm_commands.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

namespace boycott::driver {

std::optional<std::string> find_program(const std::string& name) {
  if (name.find('/') != std::string::npos)
    return access(name.c_str(), X_OK) == 0 ? std::optional<std::string>(name) : std::nullopt;
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    const std::string p = (d.empty() ? "." : d) + "/" + name;
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return std::nullopt;
}

Captured run_captured(const std::vector<std::string>& argv) {
  int out_pipe[2], err_pipe[2];
  if (pipe2(out_pipe, O_CLOEXEC) != 0 || pipe2(err_pipe, O_CLOEXEC) != 0)
    throw std::runtime_error(fmt::format("cannot run {}: {}", argv[0], std::strerror(errno)));
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(fmt::format("cannot run {}: fork failed", argv[0]));
  if (pid == 0) {
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(out_pipe[1], 1);
    dup2(err_pipe[1], 2);
    std::vector<char*> cargv;
    for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
    cargv.push_back(nullptr);
    execvp(cargv[0], cargv.data());
    std::fprintf(stderr, "cannot start '%s': %s\n", cargv[0], std::strerror(errno));
    _exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  Captured c;
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&c.out, &c.err};
  int open_fds = 2;
  while (open_fds > 0) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buf[4096];
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[i]->append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      }
    }
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  c.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return c;
}

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  const auto e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::optional<std::int64_t> to_int(const std::string& s) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno != 0) return std::nullopt;
  return v;
}

std::optional<std::vector<SlurmJob>> squeue_jobs(std::string* why) {
  const auto squeue = find_program("squeue");
  if (!squeue) {
    if (why) *why = "no squeue on PATH";
    return std::nullopt;
  }
  const Captured c = run_captured({*squeue, "--noheader", "--array", "--format=%A|%F|%K|%T|%r"});
  if (c.exit_code != 0) {
    if (why) *why = fmt::format("squeue failed (exit {}): {}", c.exit_code, trim(c.err));
    return std::nullopt;
  }
  std::vector<SlurmJob> jobs;
  std::istringstream lines(c.out);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, '|');) f.push_back(trim(x));
    if (f.size() < 4) continue;
    SlurmJob j;
    const auto id = to_int(f[0]);
    if (!id) continue;
    j.job_id = *id;
    j.array_job_id = to_int(f[1]).value_or(j.job_id);
    j.array_task_id = to_int(f[2]);  // N/A for a plain job
    j.state = f[3];
    if (f.size() > 4) j.reason = f[4];
    jobs.push_back(std::move(j));
  }
  return jobs;
}

const SlurmJob* find_slurm_job(const std::vector<SlurmJob>& jobs, std::optional<std::int64_t> array_job_id,
                               std::optional<std::int64_t> array_task_id,
                               std::optional<std::int64_t> job_id) {
  for (const auto& j : jobs) {
    if (job_id && j.job_id == *job_id) return &j;
    if (array_job_id && array_task_id && j.array_job_id == *array_job_id && j.array_task_id == array_task_id)
      return &j;
  }
  return nullptr;
}

}  // namespace boycott::driver
