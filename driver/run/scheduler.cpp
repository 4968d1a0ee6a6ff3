#include "driver/run/scheduler.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/run/recording.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

using Clock = std::chrono::steady_clock;

void write_atomic(const fs::path& p, const std::string& text) {
  const fs::path tmp = p.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw StorageError(fmt::format("cannot write '{}': {}", tmp.string(), std::strerror(errno)));
  }
  fs::rename(tmp, p);
}

/// The wait before a case that hit the n-th storage error in a row runs again: 2, 4, 8 ... s, at
/// most 64 s. BOYCOTT_TEST_STORAGE_BACKOFF_S replaces the first 2 s (tests).
std::chrono::duration<double> storage_backoff(int n) {
  double first = 2.0;
  if (const char* t = std::getenv("BOYCOTT_TEST_STORAGE_BACKOFF_S")) first = std::atof(t);
  return std::chrono::duration<double>(std::min(first * std::pow(2.0, n - 1), 64.0));
}

}  // namespace

Scheduler::Scheduler(Database& db, const Study& study, const std::vector<CaseState>& states,
                     const StudyRunOptions& opt, fs::path runs_root, std::vector<std::string> solver)
    : db_(db),
      opt_(opt),
      runs_root_(std::move(runs_root)),
      solver_(std::move(solver)),
      progress_(study.name, opt.jobs, opt.progress_live, opt.progress_every_s) {
  std::map<std::string, const StudyCase*> by_id;
  for (const auto& c : study.cases) by_id[c.id] = &c;
  // Cases stopped part-way (a signal, --stop-after, or a driver that died with the attempt open)
  // go first, then the rest, each in study order: a checkpoint's work would otherwise wait behind
  // cases started afresh, and goes with its run folder should the machine be replaced.
  std::vector<const StudyCase*> fresh;
  for (const auto& s : states) {
    failures_[s.id] = s.failures;
    if (s.status == CaseStatus::kDone)
      ++done_;
    else if (s.status == CaseStatus::kFailed)
      ++failed_;
    else if (!by_id.count(s.id))
      continue;
    else if (s.status == CaseStatus::kInterrupted || s.status == CaseStatus::kRunning)
      queue_.push_back(by_id[s.id]);
    else
      fresh.push_back(by_id[s.id]);
  }
  queue_.insert(queue_.end(), fresh.begin(), fresh.end());
}

bool Scheduler::run() {
  std::set<const StudyCase*> told_locked;
  while (!queue_.empty() || !running_.empty() || !backing_off_.empty()) {
    bool lock_wait = false;
    const bool out_of_time = opt_.stop_at && Clock::now() >= *opt_.stop_at;
    if ((stop_signal() || out_of_time) && !stopping_) stop_all();
    if (stopping_) {
      // They stay pending in the database, and in the count; none starts once stopping.
      for (const auto& b : backing_off_) queue_.push_back(b.second);
      backing_off_.clear();
    }
    // Back in the queue once their back-off has passed.
    const auto now = Clock::now();
    for (auto it = backing_off_.begin(); it != backing_off_.end();) {
      if (it->first > now) {
        ++it;
        continue;
      }
      queue_.push_back(it->second);
      it = backing_off_.erase(it);
    }
    while (!stopping_ && static_cast<int>(running_.size()) < opt_.jobs && !queue_.empty()) {
      const StudyCase* c = queue_.front();
      queue_.pop_front();
      if (!start(c)) {
        // Its folder is locked (an orphaned solver still stopping, or another driver): later.
        queue_.push_back(c);
        lock_wait = true;
        if (told_locked.insert(c).second)
          std::fprintf(stderr, "case %s: waiting for the process that holds %s to exit\n", c->id.c_str(),
                       (runs_root_ / c->id / ".lock").c_str());
        break;
      }
    }
    if (stopping_ && running_.empty()) break;
    if (const auto exited = reap_exited_solver()) {
      reap(*exited);
      continue;
    }
    progress_.redraw_if_due([this] { return counts(); }, running_);
    // A locked folder frees only when another process exits: no need to ask as often.
    std::this_thread::sleep_for(std::chrono::milliseconds(lock_wait ? 100 : 20));
  }
  progress_.draw(counts(), running_);
  return stopping_;
}

void Scheduler::stop_all() {
  stopping_ = true;
  for (const auto& j : running_) forward_stop(j.pid);
}

bool Scheduler::start(const StudyCase* c) {
  RunningCase j;
  j.c = c;
  j.dir = runs_root_ / c->id;
  fs::create_directories(j.dir);
  const auto lock_fd = lock_run_folder(j.dir);
  if (!lock_fd) return false;
  j.lock_fd = *lock_fd;
  // Another driver on the same database may have finished it meanwhile.
  if (has_result(db_, c->id)) {
    ++done_;
    unlock_run_folder(j.lock_fd);
    return true;
  }
  const fs::path case_file = j.dir / kCaseFileName;
  // Written at every attempt: the same case, in this program's form (a folder written by an
  // older version holds its own form, which this one may refuse).
  write_atomic(case_file, case_file_text(c->params));
  j.attempt = begin_attempt(db_, c->id, opt_.ranks, j.dir.string());
  // A solver that finished but whose result the driver never recorded: take it as it is.
  if (record_left_summary(db_, j.attempt, c->id, j.dir)) {
    ++done_;
    unlock_run_folder(j.lock_fd);
    return true;
  }
  const fs::path log = j.dir / "solver.log";
  j.log_offset_bytes = fs::exists(log) ? fs::file_size(log) : 0;
  j.t_start_s = simulated_time_s(j.dir);
  std::error_code ec;
  const auto mtime = fs::last_write_time(j.dir / "summary.json", ec);
  if (!ec) j.summary_before = mtime;
  const auto argv = case_command(solver_, opt_.ranks, case_file.string(), j.dir.string());
  j.pid = start_solver(argv, log, j.lock_fd);
  j.started = Clock::now();
  running_.push_back(j);
  return true;
}

void Scheduler::reap(const SolverExit& exited) {
  for (std::size_t i = 0; i < running_.size(); ++i) {
    if (running_[i].pid != exited.pid) continue;
    const RunningCase j = running_[i];
    running_.erase(running_.begin() + static_cast<std::ptrdiff_t>(i));
    finish(j, exited.exit_code);
    unlock_run_folder(j.lock_fd);
    return;
  }
}

void Scheduler::finish(const RunningCase& run, int exit_code) {
  const StudyCase* c = run.c;
  const AttemptEnd end = record_attempt_end(db_, run, exit_code);
  if (end.kind != AttemptEnd::Kind::kStorageFailed) storage_failures_in_a_row_ = 0;
  if (end.kind == AttemptEnd::Kind::kDone) {
    ++done_;
    progress_.add_finished_case(c->id, std::chrono::duration<double>(Clock::now() - run.started).count(),
                                run.t_start_s);
    return;
  }
  if (end.kind == AttemptEnd::Kind::kInterrupted) {
    // Stopped from outside (not by this driver): resume at once. Stopped by this driver: counted
    // as pending, and nothing starts once stopping.
    queue_.push_front(c);
    return;
  }
  const std::string where =
      fmt::format("case {} ({} angle={:g} deg)", c->id, c->group, c->params.gravity.angle_deg);
  if (end.kind == AttemptEnd::Kind::kStorageFailed) {
    // Not the case's fault: its last checkpoint is kept; it runs again once there is room.
    const int n = ++storage_failures_in_a_row_;
    std::fprintf(stderr, "%s: storage error (exit %d), not counted as a failure: %s\n", where.c_str(),
                 exit_code, end.reason.c_str());
    if (n >= kStorageFailuresToStop) {
      storage_stop_ = fmt::format("{} storage errors in a row (exit 74), the last: {}", n, end.reason);
      if (!stopping_) stop_all();
    }
    if (!stopping_ && !stop_signal()) {
      const auto wait = storage_backoff(n);
      std::fprintf(stderr, "%s: runs again in %g s\n", where.c_str(), wait.count());
      backing_off_.emplace_back(Clock::now() + std::chrono::duration_cast<Clock::duration>(wait), c);
    } else {
      queue_.push_back(c);  // counted as pending; nothing starts once stopping
    }
    return;
  }
  if (exit_code == 0)
    std::fprintf(stderr, "%s failed: %s\n", where.c_str(), end.reason.c_str());
  else
    std::fprintf(stderr, "%s failed (exit %d): %s\n", where.c_str(), exit_code, end.reason.c_str());
  if (end.exit_code == kExitCheckpointError) {
    // The checkpoint cannot be used: keep the folder for inspection, start the case afresh.
    std::error_code ec;
    fs::rename(run.dir, fs::path(run.dir.string() + fmt::format(".bad-{}", run.attempt)), ec);
  }
  const int failures = ++failures_[c->id];
  if (end.exit_code != kExitInputError && failures <= opt_.retries)
    queue_.push_back(c);  // while stopping, counted as pending: it retries on the next run
  else
    ++failed_;
}

ProgressCounts Scheduler::counts() const {
  ProgressCounts out{done_, failed_, queue_.size() + backing_off_.size(), stopping_, {}};
  for (const StudyCase* c : queue_) out.pending_ids.push_back(c->id);
  for (const auto& b : backing_off_) out.pending_ids.push_back(b.second->id);
  return out;
}

}  // namespace boycott::driver
