#include "driver/run/solver_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

std::atomic<int> g_stop_signal{0};
extern "C" void on_stop(int sig) {
  g_stop_signal.store(sig);
}

std::vector<std::string> split_words(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream is(s);
  for (std::string w; is >> w;) out.push_back(w);
  return out;
}

}  // namespace

std::vector<std::string> case_command(const std::vector<std::string>& solver, int ranks,
                                      const std::string& case_file, const std::string& out_dir) {
  std::vector<std::string> argv;
  if (ranks > 1) argv = {"mpirun", "-n", std::to_string(ranks), "--allow-run-as-root"};
  argv.insert(argv.end(), solver.begin(), solver.end());
  for (const char* a : {"case", "run"}) argv.emplace_back(a);
  argv.push_back(case_file);
  argv.emplace_back("--out");
  argv.push_back(out_dir);
  argv.emplace_back("--quiet");
  return argv;
}

std::vector<std::string> solver_argv(const std::string& configured) {
  std::string cmd = configured;
  if (cmd.empty())
    if (const char* e = std::getenv("BOYCOTT_SOLVER_COMMAND")) cmd = e;
  if (!cmd.empty()) return split_words(cmd);
  return {fs::read_symlink("/proc/self/exe").string()};
}

pid_t start_solver(const std::vector<std::string>& argv, const fs::path& log, int lock_fd) {
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    setpgid(0, 0);                     // Ctrl-C reaches the driver only; it forwards the stop to the case.
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // driver killed with -9: the case checkpoints and stops
    if (getppid() != parent) _exit(75);
    fcntl(lock_fd, F_SETFD, 0);  // the solver inherits the run folder's lock
    // ... and is told so: `case run` takes the lock itself unless its folder is the one named here.
    std::error_code ec;
    const auto dir = fs::weakly_canonical(log.parent_path(), ec);
    setenv(kRunFolderLockedEnv, (ec ? log.parent_path() : dir).c_str(), 1);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    std::vector<char*> cargv;
    for (const auto& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
    cargv.push_back(nullptr);
    execvp(cargv[0], cargv.data());
    std::fprintf(stderr, "cannot start '%s'\n", cargv[0]);
    _exit(127);
  }
  // Also in the parent, so that a stop forwarded before the child ran setpgid finds the group.
  setpgid(pid, pid);
  return pid;
}

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int stop_signal() {
  return g_stop_signal.load();
}

void forward_stop(pid_t pid) {
  ::kill(-pid, SIGTERM);
}

std::optional<SolverExit> reap_exited_solver() {
  int status = 0;
  const pid_t pid = waitpid(-1, &status, WNOHANG);
  if (pid <= 0) return std::nullopt;
  return SolverExit{pid, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)};
}

}  // namespace boycott::driver
