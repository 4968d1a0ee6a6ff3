#pragma once
// A run folder and what it already holds: whether it is this case's (one case per folder: its
// params.json names it), how far its run went, and whether a finished run is asked for more.
#include <filesystem>
#include <optional>

#include "core/case_params.hpp"
#include "scenes/scene.hpp"

namespace boycott::runs {

/// Refuses an --out folder that is not this case's run folder (CheckpointError: exit 4): one that
/// holds another case, a damaged params.json, or files of the user's (a folder that is not a run
/// folder of this program). Reads only.
void check_run_folder(const std::filesystem::path& dir, const CaseParams& params);

/// The time a checkpoint reached, s (nullopt when it cannot be read: resume decides then).
std::optional<double> checkpoint_time(const std::filesystem::path& checkpoint);

/// Whether the run in ctx.out_dir already reached time.end (then it says so, unless quiet);
/// refuses an end below the time it reached. A finished run continued to a later end loses the
/// off-schedule row it wrote at its old end.
bool already_complete(const CaseParams& params, const scenes::RunContext& ctx);

}  // namespace boycott::runs
