#include "driver/runner.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/curve.hpp"
#include "driver/database.hpp"
#include "driver/store.hpp"
#include "driver/study.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

std::atomic<int> g_stop_signal{0};
extern "C" void on_stop(int sig) {
  g_stop_signal.store(sig);
}

using Clock = std::chrono::steady_clock;

std::vector<std::string> split_words(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream is(s);
  for (std::string w; is >> w;) out.push_back(w);
  return out;
}

std::vector<std::string> solver_argv(const std::string& configured) {
  std::string cmd = configured;
  if (cmd.empty())
    if (const char* e = std::getenv("BOYCOTT_SOLVER_COMMAND")) cmd = e;
  if (!cmd.empty()) return split_words(cmd);
  return {fs::read_symlink("/proc/self/exe").string()};
}

void write_atomic(const fs::path& p, const std::string& text) {
  const fs::path tmp = p.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    if (!out) throw std::runtime_error(fmt::format("cannot write '{}'", tmp.string()));
  }
  fs::rename(tmp, p);
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The last non-empty line the solver wrote to its log since `offset`: its one-line reason.
std::string last_line(const fs::path& log, std::uintmax_t offset) {
  std::ifstream in(log);
  if (!in) return "";
  in.seekg(static_cast<std::streamoff>(offset));
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

/// Simulated time of a running case: first column of the last line of timeseries.csv.
double simulated_time(const fs::path& dir) {
  std::ifstream in(dir / "timeseries.csv", std::ios::ate);
  if (!in) return 0.0;
  const auto size = static_cast<std::streamoff>(in.tellg());
  const std::streamoff back = std::min<std::streamoff>(size, 4096);
  in.seekg(size - back);
  std::string chunk(static_cast<std::size_t>(back), '\0');
  in.read(chunk.data(), back);
  auto end = chunk.find_last_not_of("\n\r ");
  if (end == std::string::npos) return 0.0;
  const auto begin = chunk.rfind('\n', end);
  const std::string line = chunk.substr(begin == std::string::npos ? 0 : begin + 1, end + 1);
  char* stop = nullptr;
  const double t = std::strtod(line.c_str(), &stop);
  return stop == line.c_str() ? 0.0 : t;
}

struct Job {
  const StudyCase* c = nullptr;
  fs::path dir;
  int lock_fd = -1;
  pid_t pid = -1;
  std::int64_t attempt = 0;
  std::uintmax_t log_offset = 0;
  Clock::time_point started;
  double t_start_s = 0;  ///< simulated time when this attempt started (resume)
};

std::string fmt_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long v = std::lround(s);
  if (v >= 3600) return fmt::format("{}h{:02d}m", v / 3600, static_cast<int>(v % 3600 / 60));
  if (v >= 60) return fmt::format("{}m{:02d}s", v / 60, static_cast<int>(v % 60));
  return fmt::format("{}s", v);
}

}  // namespace

std::string runs_root(const std::string& db_path) {
  return db_path + ".runs";
}

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

int study_run(const StudyRunOptions& opt) {
  if (opt.jobs < 1) throw InputError(fmt::format("--jobs = {} must be >= 1", opt.jobs));
  if (opt.retries < 0) throw InputError(fmt::format("--retries = {} must be >= 0", opt.retries));
  if (opt.ranks < 1) throw InputError(fmt::format("--ranks = {} must be >= 1", opt.ranks));
  // The whole study is expanded and validated before the database is touched.
  const Study study = expand_study_file(opt.study_file);
  Database db(opt.db_path, OpenMode::kCreate);
  register_study(db, study);
  const fs::path root = runs_root(opt.db_path);
  fs::create_directories(root);
  const auto solver = solver_argv(opt.solver_command);

  struct sigaction sa {};
  sa.sa_handler = on_stop;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::map<std::string, const StudyCase*> by_id;
  for (const auto& c : study.cases) by_id[c.id] = &c;
  std::deque<const StudyCase*> queue;
  std::map<std::string, int> failures;
  int n_done = 0, n_failed = 0;
  for (const auto& s : case_states(db, study.name, opt.retries)) {
    failures[s.id] = s.failures;
    if (s.status == CaseStatus::kDone)
      ++n_done;
    else if (s.status == CaseStatus::kFailed)
      ++n_failed;
    else if (by_id.count(s.id))
      queue.push_back(by_id[s.id]);
  }
  const int n_total = static_cast<int>(study.cases.size());

  std::vector<Job> running;
  std::vector<double> finished_wall_s;
  int printed_lines = 0;
  auto last_draw = Clock::now() - std::chrono::seconds(1);
  bool stopping = false;

  auto launch = [&](const StudyCase* c) -> bool {
    Job j;
    j.c = c;
    j.dir = root / c->id;
    fs::create_directories(j.dir);
    j.lock_fd = ::open((j.dir / ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
    if (j.lock_fd < 0)
      throw std::runtime_error(fmt::format("cannot create '{}'", (j.dir / ".lock").string()));
    // Held by the solver as long as it lives: a solver orphaned by a killed driver is still
    // checkpointing, and a second driver must not start the case twice.
    if (::flock(j.lock_fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(j.lock_fd);
      return false;
    }
    {
      // Another driver on the same database may have finished it meanwhile.
      auto st = db.prepare("SELECT 1 FROM results WHERE case_id = ?1");
      st.bind(1, c->id);
      if (st.step()) {
        ++n_done;
        ::close(j.lock_fd);
        return true;
      }
    }
    const fs::path case_file = j.dir / "case.toml";
    if (!fs::exists(case_file)) write_atomic(case_file, case_to_toml(c->params));
    j.attempt = begin_attempt(db, c->id, opt.ranks, j.dir.string());
    // A solver that finished but whose result the driver never recorded: take it as it is.
    if (fs::exists(j.dir / "summary.json")) {
      try {
        const auto summary = nlohmann::json::parse(read_text(j.dir / "summary.json"));
        if (summary.value("status", "") == "done" && summary.value("case_id", "") == c->id) {
          record_result(db, j.attempt, c->id, summary);
          ++n_done;
          ::close(j.lock_fd);
          return true;
        }
      } catch (const nlohmann::json::exception&) {
        // Unreadable (cut short): the solver runs again and rewrites it.
      }
    }
    const fs::path log = j.dir / "solver.log";
    j.log_offset = fs::exists(log) ? fs::file_size(log) : 0;
    j.t_start_s = simulated_time(j.dir);
    const auto argv = case_command(solver, opt.ranks, case_file.string(), j.dir.string());
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
      setpgid(0, 0);                     // Ctrl-C reaches the driver only; it forwards the stop to the case.
      prctl(PR_SET_PDEATHSIG, SIGTERM);  // driver killed with -9: the case checkpoints and stops
      if (getppid() != parent) _exit(75);
      fcntl(j.lock_fd, F_SETFD, 0);  // the solver inherits the run folder's lock
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
    setpgid(pid, pid);
    j.pid = pid;
    j.started = Clock::now();
    running.push_back(j);
    return true;
  };

  auto finish = [&](Job& j, int code) {
    const StudyCase* c = j.c;
    const std::string where =
        fmt::format("case {} ({} {}={:g} deg)", c->id, c->group, "angle", c->params.gravity.angle_deg);
    if (code == 0) {
      std::string why;
      try {
        const auto summary = nlohmann::json::parse(read_text(j.dir / "summary.json"));
        if (summary.value("case_id", "") != c->id)
          why = fmt::format("summary.json is for case '{}'", summary.value("case_id", ""));
        else {
          record_result(db, j.attempt, c->id, summary);
          ++n_done;
          finished_wall_s.push_back(std::chrono::duration<double>(Clock::now() - j.started).count());
        }
      } catch (const nlohmann::json::exception& e) {
        why = "exit 0 without a readable summary.json";
      }
      if (!why.empty()) code = 1;
      if (code == 0) return;
      finish_attempt(db, j.attempt, code, why);
      std::fprintf(stderr, "%s failed: %s\n", where.c_str(), why.c_str());
    } else if (code == kExitInterrupted || code == 128 + SIGTERM || code == 128 + SIGINT) {
      // 128 + signal: stopped before it could install its handlers; it resumes like 75.
      finish_attempt(
          db, j.attempt, code,
          code == kExitInterrupted ? "interrupted after a checkpoint" : "stopped by a signal while starting");
      if (!stopping && !g_stop_signal.load()) queue.push_front(c);  // stopped from outside: resume at once
      return;
    } else {
      std::string why = last_line(j.dir / "solver.log", j.log_offset);
      if (why.empty()) why = code > 128 ? fmt::format("killed by signal {}", code - 128) : "no message";
      finish_attempt(db, j.attempt, code, why);
      std::fprintf(stderr, "%s failed (exit %d): %s\n", where.c_str(), code, why.c_str());
    }
    if (code == kExitCheckpointError) {
      // The checkpoint cannot be used: keep the folder for inspection, start the case afresh.
      std::error_code ec;
      fs::rename(j.dir, fs::path(j.dir.string() + fmt::format(".bad-{}", j.attempt)), ec);
    }
    const int f = ++failures[c->id];
    if (code != kExitInputError && f <= opt.retries && !stopping)
      queue.push_back(c);
    else
      ++n_failed;
  };

  auto draw = [&] {
    if (!opt.progress) return;
    std::string s;
    if (printed_lines > 0) s += fmt::format("\033[{}A", printed_lines);
    s += "\033[J";
    double remaining_s = 0, estimated_case_s = 0;
    int estimated = 0, unknown = 0;  // unknown: running cases without a rate yet
    std::string rows;
    for (const auto& j : running) {
      const double t = simulated_time(j.dir);
      const double wall = std::chrono::duration<double>(Clock::now() - j.started).count();
      const double rate = wall > 0 ? (t - j.t_start_s) / wall : 0;
      const double end = j.c->params.time.end_s;
      remaining_s += rate > 0 ? (end - t) / rate : 0.0;
      unknown += rate > 0 ? 0 : 1;
      if (rate > 0) {
        estimated_case_s += end / rate;
        ++estimated;
      }
      rows += fmt::format("  {} {:<12} {:5.1f} deg  t = {:8.3f} / {:g} s  {:8.4f} sim s/s\n", j.c->id,
                          j.c->group, j.c->params.gravity.angle_deg, t, end, rate);
    }
    // Mean wall time of the cases finished in this run, else an estimate from the running ones.
    double per_case = estimated > 0 ? estimated_case_s / estimated : NAN;
    if (!finished_wall_s.empty()) {
      per_case = 0;
      for (double w : finished_wall_s) per_case += w;
      per_case /= static_cast<double>(finished_wall_s.size());
    }
    const double eta = (remaining_s + static_cast<double>(queue.size() + unknown) * per_case) / opt.jobs;
    s +=
        fmt::format("study {}: {} done, {} running, {} failed, {} pending; ETA {}{}\n", study.name, n_done,
                    running.size(), n_failed, queue.size(), fmt_duration(eta), stopping ? " (stopping)" : "");
    s += rows;
    printed_lines = 1 + static_cast<int>(running.size());
    std::fputs(s.c_str(), stdout);
    std::fflush(stdout);
  };

  std::set<const StudyCase*> told_locked;
  while (!queue.empty() || !running.empty()) {
    bool lock_wait = false;
    if (g_stop_signal.load() && !stopping) {
      stopping = true;
      for (const auto& j : running) ::kill(-j.pid, SIGTERM);
    }
    while (!stopping && static_cast<int>(running.size()) < opt.jobs && !queue.empty()) {
      const StudyCase* c = queue.front();
      queue.pop_front();
      if (!launch(c)) {
        // Its folder is locked (an orphaned solver still stopping, or another driver): later.
        queue.push_back(c);
        lock_wait = true;
        if (told_locked.insert(c).second)
          std::fprintf(stderr, "case %s: waiting for the process that holds %s to exit\n", c->id.c_str(),
                       (root / c->id / ".lock").c_str());
        break;
      }
    }
    if (stopping && running.empty()) break;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      for (std::size_t i = 0; i < running.size(); ++i) {
        if (running[i].pid != pid) continue;
        Job j = running[i];
        running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        finish(j, code);
        ::close(j.lock_fd);
        break;
      }
      continue;
    }
    if (Clock::now() - last_draw > std::chrono::milliseconds(500)) {
      draw();
      last_draw = Clock::now();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(lock_wait ? 100 : 20));
  }
  draw();

  const auto states = case_states(db, study.name, opt.retries);
  int done = 0, failed = 0;
  for (const auto& s : states) {
    done += s.status == CaseStatus::kDone;
    failed += s.status == CaseStatus::kFailed;
  }
  if (stopping) {
    std::printf("study %s stopped by signal %d: %d of %d cases done; run the same command to resume\n",
                study.name.c_str(), g_stop_signal.load(), done, n_total);
    return kExitInterrupted;
  }
  std::printf("study %s: %d of %d cases done, %d failed\n", study.name.c_str(), done, n_total, failed);
  std::fputs(format_curve(query_curve(db, study.name), CurveFormat::kTable).c_str(), stdout);
  return failed > 0 ? kExitFailure : kExitOk;
}

int study_status(const std::string& study_file, const std::string& db_path, int retries) {
  const Study study = expand_study_file(study_file);
  Database db(db_path, OpenMode::kExisting);
  std::map<std::string, CaseState> known;
  for (auto& s : case_states(db, study.name, retries)) known[s.id] = s;
  std::map<std::string, int> counts;
  std::string lines;
  for (const auto& c : study.cases) {
    auto it = known.find(c.id);
    const char* st = it == known.end() ? "pending" : to_string(it->second.status);
    if (it != known.end() && it->second.status == CaseStatus::kRunning) {
      // An open attempt whose folder nobody holds: its driver died (kill -9, power loss).
      const int fd = ::open((fs::path(runs_root(db_path)) / c.id / ".lock").c_str(), O_RDWR | O_CLOEXEC);
      if (fd >= 0 && ::flock(fd, LOCK_EX | LOCK_NB) == 0) st = "interrupted";
      if (fd >= 0) ::close(fd);
    }
    ++counts[st];
    lines +=
        fmt::format("{:<16} {:<12} {:6.1f} {:<12} {}\n", c.id, c.group, c.params.gravity.angle_deg, st,
                    it != known.end() && it->second.status != CaseStatus::kDone ? it->second.last_error : "");
  }
  std::printf("study %s: %zu cases: %d done, %d running, %d failed, %d interrupted, %d pending\n",
              study.name.c_str(), study.cases.size(), counts["done"], counts["running"], counts["failed"],
              counts["interrupted"], counts["pending"]);
  std::printf("%-16s %-12s %6s %-12s %s\n", "case", "group", "angle", "status", "last error");
  std::fputs(lines.c_str(), stdout);
  return 0;
}

}  // namespace boycott::driver
