#include "driver/run/recording.hpp"

#include <signal.h>

#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "driver/store/store.hpp"

namespace fs = std::filesystem;

namespace boycott::driver {
namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The last non-empty line the solver wrote to its log since `offset_bytes`: its one-line reason.
/// With prefer_error, the last line that starts "error: " when there is one (mpirun adds its own
/// lines after the solver's reason when a rank aborts). Up to `end_bytes` when set.
std::string last_line(const fs::path& log, std::uintmax_t offset_bytes, bool prefer_error = false,
                      std::optional<std::uintmax_t> end_bytes = std::nullopt) {
  std::ifstream in(log);
  if (!in) return "";
  in.seekg(static_cast<std::streamoff>(offset_bytes));
  std::string line, last, last_error;
  while ((!end_bytes || static_cast<std::uintmax_t>(in.tellg()) < *end_bytes) && std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
    if (line.rfind("error: ", 0) == 0) last_error = line;
  }
  return prefer_error && !last_error.empty() ? last_error : last;
}

/// Whether this attempt wrote a summary.json of its case with status "interrupted".
bool wrote_interrupted_summary(const RunningCase& run) {
  std::error_code ec;
  const auto mtime = fs::last_write_time(run.dir / "summary.json", ec);
  if (ec || (run.summary_before && *run.summary_before == mtime)) return false;
  try {
    const auto summary = nlohmann::json::parse(read_text(run.dir / "summary.json"));
    return summary.value("status", "") == kStatusInterrupted && summary.value("case_id", "") == run.c->id;
  } catch (const nlohmann::json::exception&) {
    return false;
  }
}

}  // namespace

AttemptEnd record_attempt_end(Database& db, const RunningCase& run, int exit_code) {
  const StudyCase* c = run.c;
  if (exit_code == 0) {
    std::string why;
    try {
      const auto summary = nlohmann::json::parse(read_text(run.dir / "summary.json"));
      if (summary.value("case_id", "") != c->id)
        why = fmt::format("summary.json is for case '{}'", summary.value("case_id", ""));
      else if (!is_finished_status(summary.value("status", "")))
        why = fmt::format("exit 0 but summary.json has status '{}'", summary.value("status", ""));
      else
        record_result(db, run.attempt, c->id, summary);
    } catch (const nlohmann::json::exception&) {
      why = "exit 0 without a readable summary.json";
    }
    if (why.empty()) return {AttemptEnd::Kind::kDone, 0, ""};
    finish_attempt(db, run.attempt, 1, why);
    return {AttemptEnd::Kind::kFailed, 1, why};
  }
  if (exit_code == kExitStorageError) {
    // The storage failed, not the case: the solver kept its last good checkpoint.
    std::string why = last_line(run.dir / "solver.log", run.log_offset_bytes, true, run.log_end_bytes);
    if (why.empty()) why = "storage error (exit 74)";
    finish_attempt(db, run.attempt, exit_code, why);
    return {AttemptEnd::Kind::kStorageFailed, exit_code, why};
  }
  // A case run under mpirun that stopped on the driver's signal: mpirun, signalled too, exits
  // with 1 whatever its ranks returned; the summary this attempt wrote says what happened.
  if (exit_code != kExitInterrupted && wrote_interrupted_summary(run)) exit_code = kExitInterrupted;
  // 128 + SIGUSR1: a Slurm task's wall-time warning reached the solver before its handlers.
  if (exit_code == kExitInterrupted || exit_code == 128 + SIGTERM || exit_code == 128 + SIGINT ||
      exit_code == 128 + SIGUSR1) {
    finish_attempt(db, run.attempt, exit_code,
                   exit_code == kExitInterrupted ? "interrupted after a checkpoint"
                                                 : "stopped by a signal while starting");
    return {AttemptEnd::Kind::kInterrupted, exit_code, ""};
  }
  std::string why = last_line(run.dir / "solver.log", run.log_offset_bytes, false, run.log_end_bytes);
  if (why.empty()) why = exit_code > 128 ? fmt::format("killed by signal {}", exit_code - 128) : "no message";
  finish_attempt(db, run.attempt, exit_code, why);
  return {AttemptEnd::Kind::kFailed, exit_code, why};
}

bool record_left_summary(Database& db, std::int64_t attempt, const std::string& case_id,
                         const fs::path& run_dir) {
  if (!fs::exists(run_dir / "summary.json")) return false;
  try {
    const auto text = read_text(run_dir / "summary.json");
    const auto summary = nlohmann::json::parse(text);
    // A run that finished at an earlier time.end than the case now has is continued, not recorded.
    if (is_finished_status(summary.value("status", "")) && summary.value("case_id", "") == case_id &&
        summary_reaches_end(db, case_id, text)) {
      record_result(db, attempt, case_id, summary);
      return true;
    }
  } catch (const nlohmann::json::exception&) {
    // Unreadable (cut short): the solver runs again and rewrites it.
  }
  return false;
}

}  // namespace boycott::driver
