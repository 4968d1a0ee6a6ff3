#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/run_status.hpp"
#include "io/checkpoint_file.hpp"
#include "scenes/preflight.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"
#include "scenes/scenes_list.hpp"

namespace boycott::scenes {

namespace {
const std::map<std::string, SceneFn>& scene_table() {
  static const std::map<std::string, SceneFn> table = {
      {"dem_only", &run_dem_only},
      {"channel_flow", &run_channel_flow},
      {"inclined_settling", &run_inclined_settling},
      {"single_particle", &run_single_particle},
      {"ergun", &run_ergun},
      {"sediment_transport", &run_sediment_transport},
  };
  return table;
}
}  // namespace

SceneFn find_scene(const std::string& name) {
  scene_spec(name);  // names the known scenes when it is not one
  auto it = scene_table().find(name);
  if (it == scene_table().end())
    throw InputError(fmt::format("scene '{}' has no code in the scene table", name));
  return it->second;
}

std::vector<std::string> registered_scenes() {
  std::vector<std::string> names;
  for (const auto& [name, fn] : scene_table()) names.push_back(name);
  return names;
}

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

/// Refuses an --out folder that is not this case's run folder (CheckpointError: exit 4): one that
/// holds another case, a damaged params.json, or files of the user's (a folder that is not a run
/// folder of this program). Reads only.
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

/// The time a checkpoint reached, s (nullopt when it cannot be read: resume decides then).
std::optional<double> checkpoint_time(const std::filesystem::path& ck) {
  try {
    io::CheckpointReader r(ck);
    return r.scalar("run.time_s");
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// `--from DIR [--at TIME]`: the parent checkpoint, and the parent recorded in the case. What a
/// running case cannot change (its particles, grid and domain; a larger diameter would overlap
/// them) is refused naming the parameter.
void prepare_branch(CaseParams& params, RunContext& ctx) {
  const auto cks = io::checkpoints_newest_first(ctx.branch_from);
  if (cks.empty())
    throw InputError(fmt::format("--from {}: it holds no checkpoint", ctx.branch_from.string()));
  std::string kept;
  for (const auto& ck : cks) {
    const auto t = checkpoint_time(ck);
    if (!t) continue;
    kept += fmt::format("{}{:g}", kept.empty() ? "" : ", ", *t);
    if (is_set(ctx.branch_at_s) && *t > ctx.branch_at_s * (1.0 + 1e-12) + 1e-12) continue;
    io::CheckpointReader r(ck);
    CaseParams parent = case_from_json(nlohmann::json::parse(r.string("case_json")));
    const auto refuse = [&](const char* key, const std::string& was, const std::string& now) {
      throw InputError(fmt::format("--from {}: {} cannot change in a branch ({} in the parent, {} here)",
                                   ctx.branch_from.string(), key, was, now));
    };
    if (parent.scene != params.scene) refuse("scene", parent.scene, params.scene);
    if (parent.particles.count != params.particles.count)
      refuse("particles.count", std::to_string(parent.particles.count),
             std::to_string(params.particles.count));
    if (parent.domain.cells != params.domain.cells)
      refuse("domain.cells", to_json(parent)["domain"]["cells"].dump(),
             to_json(params)["domain"]["cells"].dump());
    for (auto [key, a, b] :
         {std::tuple{"domain.length_x", parent.domain.length_x_m, params.domain.length_x_m},
          {"domain.width_y", parent.domain.width_y_m, params.domain.width_y_m},
          {"domain.height_z", parent.domain.height_z_m, params.domain.height_z_m}})
      if (a != b) refuse(key, fmt::format("{:g} m", a), fmt::format("{:g} m", b));
    if (parent.domain.periodic_y != params.domain.periodic_y)
      refuse("domain.periodic_y", parent.domain.periodic_y ? "true" : "false",
             params.domain.periodic_y ? "true" : "false");
    if (params.particles.diameter_m > parent.particles.diameter_m)
      refuse("particles.diameter (larger)", fmt::format("{:g} m", parent.particles.diameter_m),
             fmt::format("{:g} m", params.particles.diameter_m));
    params.branch.parent_id = case_id(parent);
    params.branch.parent_time_s = *t;
    ctx.branch_checkpoint = ck;
    return;
  }
  throw InputError(fmt::format("--at {:g} s: {} keeps checkpoints at {} s only, none at or before it",
                               ctx.branch_at_s, ctx.branch_from.string(),
                               kept.empty() ? "no readable" : kept));
}

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

/// Whether the run in `dir` already reached time.end (then it says so); refuses an end below
/// the time it reached.
bool already_complete(const CaseParams& params, const RunContext& ctx) {
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

}  // namespace

int run_case(CaseParams params, RunContext& ctx) {
  int ranks = 1, initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // Refused before anything is written: a case that cannot work leaves the folder as it was.
  const Preflight pre = check_case(params, ranks);
  if (!pre.machine_errors.empty()) throw InputError(pre.machine_errors.front());
  const SceneFn fn = find_scene(params.scene);
  if (!ctx.branch_from.empty()) prepare_branch(params, ctx);
  // The folder is judged by rank 0 alone, and the others follow its answer: a rank that looked for
  // itself while rank 0 wrote params.json would see only its temporary file, refuse the folder
  // alone and leave rank 0 waiting in the barrier below forever. When rank 0 refuses it, the
  // others wait in the broadcast until its error ends them all (case run's MPI_Abort).
  int rank = 0;
  if (initialized) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int complete = 0;
  if (rank == 0) {
    check_run_folder(ctx.out_dir, params);
    complete = already_complete(params, ctx) ? 1 : 0;
  }
  if (initialized && ranks > 1) MPI_Bcast(&complete, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (complete != 0) return kExitOk;
  std::filesystem::create_directories(ctx.out_dir);
  const auto params_path = ctx.out_dir / "params.json";
  const auto canonical = to_json(params);
  {
    // Also over an existing one: the same case, perhaps with a raised time.end.
    // One writer: under mpirun every rank runs this, and they would race on the temporary file.
    if (rank == 0) write_file_atomic(params_path, canonical.dump(2) + "\n");
    if (initialized) MPI_Barrier(MPI_COMM_WORLD);
  }
  if (rank == 0) {
    write_file_atomic(ctx.out_dir / "preflight.json", pre.to_json().dump(2) + "\n");
    if (!ctx.quiet)
      for (const auto& w : pre.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  }
  return fn(params, ctx);
}

}  // namespace boycott::scenes
