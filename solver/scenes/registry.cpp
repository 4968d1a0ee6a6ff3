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

int run_case(CaseParams params, RunContext& ctx) {
  validate(params);
  const SceneFn fn = find_scene(params.scene);
  // Refused before anything is written: a case that cannot work leaves the folder as it was.
  const Preflight pre = preflight(params);
  if (!pre.errors.empty()) throw InputError(pre.errors.front());
  std::filesystem::create_directories(ctx.out_dir);
  const auto params_path = ctx.out_dir / "params.json";
  const auto canonical = to_json(params);
  if (std::filesystem::exists(params_path)) {
    // A run folder belongs to one case: resuming another case's folder would mix results.
    std::ifstream in(params_path);
    nlohmann::json stored;
    try {
      stored = nlohmann::json::parse(in);
    } catch (const std::exception&) {
      throw CheckpointError(fmt::format("{} is unreadable; refusing to overwrite it", params_path.string()));
    }
    // By identity, not by the JSON text: a folder written before a key was added lacks that key
    // (case_id() hashes late keys only when they differ from their defaults).
    if (case_id(case_from_json(stored)) != case_id(params))
      throw CheckpointError(fmt::format("{} holds case {} but this is case {}; use another --out folder",
                                        ctx.out_dir.string(), case_id(case_from_json(stored)),
                                        case_id(params)));
  } else {
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
