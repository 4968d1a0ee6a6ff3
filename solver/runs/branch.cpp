#include "runs/branch.hpp"

#include <string>
#include <tuple>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/checkpoint_file.hpp"
#include "runs/run_folder.hpp"

namespace boycott::runs {

void prepare_branch(CaseParams& params, scenes::RunContext& ctx) {
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

}  // namespace boycott::runs
