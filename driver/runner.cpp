#include "driver/runner.hpp"

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "driver/case_id_migration.hpp"
#include "driver/curve.hpp"
#include "driver/database.hpp"
#include "driver/scheduler.hpp"
#include "driver/solver_process.hpp"
#include "driver/store.hpp"
#include "driver/study.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {

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
  const fs::path root = runs_root(opt.db_path);
  // Ids of an older identity scheme become this one's before the study's cases are matched.
  const IdMigration moved = migrate_case_ids(db, root);
  if (moved.cases > 0)
    std::fprintf(stderr,
                 "case identity version %d: %d case ids recomputed (%d merged), %d run folders renamed\n",
                 kCaseIdVersion, moved.cases, moved.merged, moved.folders);
  register_study(db, study);
  fs::create_directories(root);
  auto solver = solver_argv(opt.solver_command);
  install_stop_handlers();

  Scheduler scheduler(db, study, case_states(db, study.name, opt.retries), opt, root, std::move(solver));
  const bool stopped = scheduler.run();
  if (!scheduler.storage_stop().empty()) {
    std::fprintf(stderr, "error: study %s stopped: %s; once the storage works again, run the same command\n",
                 study.name.c_str(), scheduler.storage_stop().c_str());
    return kExitStorageError;
  }

  const int n_total = static_cast<int>(study.cases.size());
  int done = 0, failed = 0;
  for (const auto& s : case_states(db, study.name, opt.retries)) {
    done += s.status == CaseStatus::kDone;
    failed += s.status == CaseStatus::kFailed;
  }
  if (stopped) {
    std::printf("study %s stopped by signal %d: %d of %d cases done; run the same command to resume\n",
                study.name.c_str(), stop_signal(), done, n_total);
    return kExitInterrupted;
  }
  std::printf("study %s: %d of %d cases done, %d failed\n", study.name.c_str(), done, n_total, failed);
  std::fputs(format_curve(query_curve(db, study.name), CurveFormat::kTable).c_str(), stdout);
  return failed > 0 ? kExitFailure : kExitOk;
}

int study_status(const std::string& study_file, const std::string& db_path, int retries) {
  const Study study = expand_study_file(study_file);
  Database db(db_path, OpenMode::kReadOnly);
  std::map<std::string, CaseState> known;
  for (auto& s : case_states(db, study.name, retries)) known[s.id] = s;
  std::map<std::string, int> counts;
  std::string lines;
  for (const auto& c : study.cases) {
    auto it = known.find(c.id);
    const char* st = it == known.end() ? "pending" : to_string(it->second.status);
    // An open attempt whose folder nobody holds: its driver died (kill -9, power loss).
    if (it != known.end() && it->second.status == CaseStatus::kRunning &&
        run_folder_unheld(fs::path(runs_root(db_path)) / c.id))
      st = "interrupted";
    ++counts[st];
    const std::string ranks =
        it != known.end() && it->second.ranks > 0 ? std::to_string(it->second.ranks) : "-";
    lines += fmt::format(
        "{:<16} {:<12} {:6.1f} {:<12} {:>5} {}\n", c.id, c.group, c.params.gravity.angle_deg, st, ranks,
        it != known.end() && it->second.status != CaseStatus::kDone ? it->second.last_error : "");
  }
  std::printf("study %s: %zu cases: %d done, %d running, %d failed, %d interrupted, %d pending\n",
              study.name.c_str(), study.cases.size(), counts["done"], counts["running"], counts["failed"],
              counts["interrupted"], counts["pending"]);
  std::printf("%-16s %-12s %6s %-12s %5s %s\n", "case", "group", "angle", "status", "ranks", "last error");
  std::fputs(lines.c_str(), stdout);
  return 0;
}

}  // namespace boycott::driver
