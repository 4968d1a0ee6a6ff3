#pragma once
// One entry function per scene, each in its own file in this folder.
#include "scenes/scene.hpp"

namespace boycott::scenes {
int run_dem_only(const CaseParams& p, RunContext& ctx);
int run_channel_flow(const CaseParams& p, RunContext& ctx);
int run_inclined_settling(const CaseParams& p, RunContext& ctx);
int run_single_particle(const CaseParams& p, RunContext& ctx);
int run_ergun(const CaseParams& p, RunContext& ctx);
int run_sediment_transport(const CaseParams& p, RunContext& ctx);
}  // namespace boycott::scenes
