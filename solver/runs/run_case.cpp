#include "runs/run_case.hpp"

#include <mpi.h>

#include <cstdio>
#include <filesystem>
#include <utility>

#include "checks/check_case.hpp"
#include "core/error.hpp"
#include "runs/branch.hpp"
#include "runs/run_folder.hpp"
#include "scenes/run_common.hpp"

namespace boycott::runs {

int run_ranks() {
  int ranks = 1, initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  return ranks;
}

int run_case(CaseParams params, const checks::Preflight& pre, scenes::RunContext& ctx) {
  // Refused before anything is written: a case that cannot work leaves the folder as it was.
  if (!pre.errors.empty()) throw InputError(pre.errors.front());
  if (!pre.machine_errors.empty()) throw InputError(pre.machine_errors.front());
  const scenes::SceneFn fn = scenes::find_scene(params.scene);
  int initialized = 0;
  MPI_Initialized(&initialized);
  const int ranks = run_ranks();
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
    if (rank == 0) scenes::write_file_atomic(params_path, canonical.dump(2) + "\n");
    if (initialized) MPI_Barrier(MPI_COMM_WORLD);
  }
  if (rank == 0) {
    scenes::write_file_atomic(ctx.out_dir / "preflight.json", pre.to_json().dump(2) + "\n");
    if (!ctx.quiet)
      for (const auto& w : pre.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  }
  return fn(params, ctx);
}

int run_case(CaseParams params, scenes::RunContext& ctx) {
  const checks::Preflight pre = checks::check_case(params, run_ranks());
  return run_case(std::move(params), pre, ctx);
}

}  // namespace boycott::runs
