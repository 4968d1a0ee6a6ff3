#include <mpi.h>

#include <cstdio>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "core/error.hpp"
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

/// What may be in a run folder before its first run: the driver's lock, case file and log, and
/// checkpoints to start from (a folder prepared by hand).
bool is_preparation_file(const std::string& name) {
  return name == ".lock" || name == "case.toml" || name == "solver.log" || name == "checkpoints";
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

}  // namespace

int run_case(CaseParams params, RunContext& ctx) {
  validate(params);
  const SceneFn fn = find_scene(params.scene);
  int ranks = 1, initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // Refused before anything is written: a case that cannot work leaves the folder as it was.
  const Preflight pre = preflight(params, ranks);
  if (!pre.errors.empty()) throw InputError(pre.errors.front());
  if (!pre.machine_errors.empty()) throw InputError(pre.machine_errors.front());
  check_run_folder(ctx.out_dir, params);
  std::filesystem::create_directories(ctx.out_dir);
  const auto params_path = ctx.out_dir / "params.json";
  const auto canonical = to_json(params);
  if (!std::filesystem::exists(params_path)) {
    // One writer: under mpirun every rank runs this, and they would race on the temporary file.
    int rank = 0, initialized = 0;
    MPI_Initialized(&initialized);
    if (initialized) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0) write_file_atomic(params_path, canonical.dump(2) + "\n");
    if (initialized) MPI_Barrier(MPI_COMM_WORLD);
  }
  {
    int rank = 0, initialized = 0;
    MPI_Initialized(&initialized);
    if (initialized) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0) {
      write_file_atomic(ctx.out_dir / "preflight.json", pre.to_json().dump(2) + "\n");
      if (!ctx.quiet)
        for (const auto& w : pre.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    }
  }
  return fn(params, ctx);
}

}  // namespace boycott::scenes
