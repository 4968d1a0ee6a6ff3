#include "runs/run_folder.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "io/checkpoint_file.hpp"
#include "scenes/run_common.hpp"

namespace boycott::runs {

using scenes::output_rank;
using scenes::write_file_atomic;

namespace {

/// What may be in a run folder before its first run: the driver's lock, case file (case.json;
/// case.toml from a driver of an earlier version) and log, a
/// Slurm task's attempt records, checkpoints to start from (a folder prepared by hand), and the
/// temporary of a params.json whose atomic write was cut short by a crash (incomplete by
/// construction: the run writes params.json afresh over it).
bool is_preparation_file(const std::string& name) {
  return name == ".lock" || name == "case.json" || name == "case.toml" || name == "solver.log" ||
         name == "checkpoints" || name == "attempts" || name == "attempt.json" || name == "params.json.tmp";
}

}  // namespace

void check_run_folder(const std::filesystem::path& dir, const CaseParams& params) {
  namespace fs = std::filesystem;
  if (!fs::exists(dir)) return;
  if (!fs::is_directory(dir))
    throw CheckpointError(fmt::format("--out {} exists and is not a folder", dir.string()));
  const auto params_path = dir / "params.json";
  if (!fs::exists(params_path)) {
    for (const auto& e : fs::directory_iterator(dir))
      if (!is_preparation_file(e.path().filename().string()))
        throw CheckpointError(
            fmt::format("--out {} is not empty and is not a run folder of boycott (it has no "
                        "params.json, and holds {}): refusing to write into it; use another "
                        "--out folder",
                        dir.string(), e.path().filename().string()));
    return;
  }
  // A run folder belongs to one case: resuming another case's folder would mix results.
  std::string stored_id;
  try {
    std::ifstream in(params_path);
    stored_id = case_id(case_from_json(nlohmann::json::parse(in)));
  } catch (const std::exception& e) {
    // A damaged folder is unusable, never bad input: the case itself may be fine.
    throw CheckpointError(
        fmt::format("{} is damaged ({}); refusing to overwrite it", params_path.string(), e.what()));
  }
  // By identity, not by the JSON text: a folder written by another version holds another form.
  if (stored_id != case_id(params))
    throw CheckpointError(fmt::format("{} holds case {} but this is case {}; use another --out folder",
                                      dir.string(), stored_id, case_id(params)));
}

std::optional<double> checkpoint_time(const std::filesystem::path& checkpoint) {
  try {
    io::CheckpointReader r(checkpoint);
    return r.scalar("run.time_s");
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

namespace {

/// Drops the last row of a time series when it came less than output.timeseries_every after the
/// one before (the row a run writes at its end, off the schedule).
void drop_off_schedule_last_row(const std::filesystem::path& csv, const CaseParams& params) {
  if (!is_set(params.output.timeseries_every_s)) return;  // a row every step: all on schedule
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  if (lines.size() < 3) return;
  const double last = std::strtod(lines.back().c_str(), nullptr),
               prev = std::strtod(lines[lines.size() - 2].c_str(), nullptr);
  if (last - prev >= params.output.timeseries_every_s - 1e-12) return;
  in.close();
  std::string text;
  for (std::size_t k = 0; k + 1 < lines.size(); ++k) text += lines[k] + "\n";
  write_file_atomic(csv, text);
}

}  // namespace

bool already_complete(const CaseParams& params, const scenes::RunContext& ctx) {
  const double end = params.time.end_s;
  double reached = -1.0, target = kUnset;
  std::string status;
  try {
    std::ifstream in(ctx.out_dir / "summary.json");
    if (in) {
      const auto j = nlohmann::json::parse(in);
      if (j.value("case_id", "") == case_id(params)) {
        status = j.value("status", "");
        reached = j.value("simulated_time_s", -1.0);
        if (j.contains("target_rel_error") && j["target_rel_error"].is_number())
          target = j["target_rel_error"];
      }
    }
  } catch (const std::exception&) {
    // Unreadable: the run writes it again.
  }
  const auto cks = io::checkpoints_newest_first(ctx.out_dir);
  if (!cks.empty())
    if (const auto t = checkpoint_time(cks.front())) reached = std::max(reached, *t);
  // The time loop may pass time.end by up to one fluid step (it stops at the first step at or
  // beyond it): only an end below that is a request to go back.
  const double step_s = std::max(params.time.dt_cfd_s, params.time.dt_dem_s);
  if (reached > end + step_s + kEndToleranceS)
    throw InputError(
        fmt::format("time.end = {:g} s is below the time this run reached, {:g} s ({}): raise it, or "
                    "use another --out folder",
                    end, reached, ctx.out_dir.string()));
  if (is_finished_status(status) && reached_end(reached, end)) {
    if (!ctx.quiet && output_rank())
      std::fprintf(stderr, "%s is already complete at t = %g s (time.end = %g s)\n", ctx.out_dir.c_str(),
                   reached, end);
    return true;
  }
  // Stopped by time.target_rel_error, and not asked for more now (a stricter target, or none,
  // continues it).
  if (status == kStatusConverged && params.time.target_rel_error >= target) {
    if (!ctx.quiet && output_rank())
      std::fprintf(stderr, "%s converged at t = %g s (time.target_rel_error = %g)\n", ctx.out_dir.c_str(),
                   reached, target);
    return true;
  }
  // A finished run continued to a later end: its last row stood for the old end only (off the
  // output schedule), and a run straight to the new end has no such row.
  if (is_finished_status(status) && output_rank())
    drop_off_schedule_last_row(ctx.out_dir / "timeseries.csv", params);
  return false;
}

}  // namespace boycott::runs
