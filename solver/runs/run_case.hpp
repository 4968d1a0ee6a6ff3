#pragma once
// Running a case in a run folder: the entry of `case run` (and of the tests that run scenes).
// The case's pre-flight on this run's ranks refuses what cannot work before anything is written;
// the folder must be this case's (or new); a run that already reached time.end is not run again;
// a branch (`--from`) starts from another run's checkpoint; then the scene named by the case runs.
#include "checks/preflight.hpp"
#include "core/case_params.hpp"
#include "scenes/scene.hpp"

namespace boycott::runs {

/// Runs (or resumes) a case whose key rules were applied (validate(), load_case_file) and whose
/// pre-flight on this run's ranks is `pre` (checks::preflight_case): its errors and machine
/// errors are refused. Writes params.json and preflight.json beside the outputs (refusing a folder
/// that holds another case) and runs the scene. A folder whose run already reached time.end says
/// so and returns 0; a time.end below the time it reached is refused; with ctx.branch_from, the
/// parent checkpoint is chosen and checked against the case (what cannot change mid-run is
/// refused). Returns the process exit code (core/error.hpp).
int run_case(CaseParams params, const checks::Preflight& pre, scenes::RunContext& ctx);

/// The whole check of a case (checks::check_case on this run's ranks), then the above: for a
/// case that has not been checked yet.
int run_case(CaseParams params, scenes::RunContext& ctx);

/// The MPI ranks this process runs on (1 without MPI).
int run_ranks();

}  // namespace boycott::runs
