#pragma once
// The `boycott case` subcommands (run, check, summarize, keys), each one case in this process:
// what case_cli.cpp calls once the command line is parsed.
#include <string>
#include <vector>

namespace boycott::driver {

struct CaseRunOptions {
  std::string case_file;
  std::string out_dir;
  std::vector<std::string> overrides;
  std::vector<std::string> petsc_options;
  bool quiet = false;
  double progress_every_s = 30.0;  ///< between plain progress lines (stderr not a terminal)
  std::string from_dir;            ///< branch from this run folder's checkpoint (empty: none)
  double at_s = -1.0;              ///< ... the newest at or before this time, s (< 0: the newest)
  double stop_after_s = 0.0;       ///< > 0: checkpoint and stop (exit 75) after this wall time, s
};

/// `boycott case run`: exit code as README.md, "Running a case", lists them.
int case_run(const CaseRunOptions& opt, int argc, char** argv);
/// `boycott case check`: validates and prints the pre-flight report.
int case_check(const std::string& file, const std::vector<std::string>& sets);
/// `boycott case summarize`: each run folder's statistics of <<w_p>> recomputed
/// (scenes/summarize.hpp); summary.json rewritten (the previous kept as summary.previous.json) and,
/// with `db`, the run's result row updated. Exit 2 naming the folder when one cannot be.
int case_summarize(const std::vector<std::string>& run_dirs, const std::string& db);
/// `boycott case keys`: every key with its default, or those `scene` reads at its defaults.
int case_keys(const std::string& scene, const std::string& format = "table");

}  // namespace boycott::driver
