#pragma once
// A run branched from another run's checkpoint: `case run --from DIR [--at TIME]`.
#include "core/case_params.hpp"
#include "scenes/scene.hpp"

namespace boycott::runs {

/// Chooses the parent checkpoint (DIR's newest kept one at or before TIME) into
/// ctx.branch_checkpoint and records the parent in the case (params.branch). What a running case
/// cannot change (its particles, grid and domain; a larger diameter would overlap them) is
/// refused naming the parameter.
void prepare_branch(CaseParams& params, scenes::RunContext& ctx);

}  // namespace boycott::runs
