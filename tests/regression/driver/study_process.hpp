#pragma once
// Whole studies run by the real `boycott` binary in a child process against fake_solver.py (the
// tests of test_study_runs.cpp and test_refine_runs.cpp): a scratch folder, the command run with
// its environment, its exit status and output, and counts read from its database.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "driver/store/database.hpp"

namespace study_process {

namespace bd = boycott::driver;
namespace fs = std::filesystem;

inline const std::string kSolver = std::string("python3 ") + FAKE_SOLVER;

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/boycott_runtest_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() {
    std::error_code ec;  // a solver a kill left behind may still be writing its last checkpoint
    fs::remove_all(path, ec);
  }
};

inline void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}
inline std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Run {
  int rc = -1;
  std::string out, err;
};

/// Starts `program args...` (the boycott binary unless given) with extra environment; stdout and
/// stderr go to files in dir. A non-zero `address_space_bytes` limits the child's virtual memory
/// (RLIMIT_AS): an allocation beyond it fails (std::bad_alloc) instead of swapping the machine.
inline pid_t spawn(std::vector<std::string> args, const fs::path& dir,
                   const std::map<std::string, std::string>& env, const std::string& program = BOYCOTT_BIN,
                   rlim_t address_space_bytes = 0) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (address_space_bytes > 0) {
      const rlimit limit{address_space_bytes, address_space_bytes};
      if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(125);
    }
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    for (const auto& [k, v] : env) setenv(k.c_str(), v.c_str(), 1);
    if (!freopen((dir / "stdout.txt").c_str(), "w", stdout) ||
        !freopen((dir / "stderr.txt").c_str(), "w", stderr))
      _exit(126);
    args.insert(args.begin(), program);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

inline Run wait_run(pid_t pid, const fs::path& dir) {
  int st = 0;
  waitpid(pid, &st, 0);
  Run r;
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.out = read(dir / "stdout.txt");
  r.err = read(dir / "stderr.txt");
  return r;
}

inline Run run(const std::vector<std::string>& args, const fs::path& dir,
               std::map<std::string, std::string> env = {}) {
  env.try_emplace("FAKE_STEP_WALL_S", "0.01");
  return wait_run(spawn(args, dir, env), dir);
}

inline std::vector<std::string> study_run(const fs::path& study, const fs::path& db, int jobs = 2) {
  return {"study",     "run",    study.string(),       "--db",
          db.string(), "--jobs", std::to_string(jobs), "--solver-command",
          kSolver};
}

inline std::int64_t count(const fs::path& db, const std::string& sql) {
  bd::Database d(db.string(), bd::OpenMode::kExisting);
  auto st = d.prepare(sql);
  st.step();
  return st.integer(0);
}

}  // namespace study_process
