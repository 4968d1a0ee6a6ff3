// The channel_flow scene end to end (as `boycott case run` runs it): summary.json carries the
// measured velocities and the error against the steady plane Poiseuille profile.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {
namespace {

using runs::run_case;

nlohmann::json run_case_file(const std::string& file, const std::string& tag) {
  CaseParams p = parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/" + file);
  RunContext ctx;
  ctx.quiet = true;
  ctx.out_dir = std::filesystem::temp_directory_path() / ("boycott_channel_scene_" + tag);
  std::filesystem::remove_all(ctx.out_dir);
  EXPECT_EQ(run_case(p, ctx), 0);
  std::ifstream in(ctx.out_dir / "summary.json");
  EXPECT_TRUE(std::filesystem::exists(ctx.out_dir / "timeseries.csv"));
  return nlohmann::json::parse(in);
}

TEST(ChannelFlowScene, PoiseuilleCaseWithinThreePercentOfAnalytic) {
  // 6 cells across, run to 4 W^2/nu: the steady error of the half-cell wall closure, 1/36.
  const auto j = run_case_file("channel_flow.toml", "poiseuille");
  EXPECT_EQ(j["scene"], "channel_flow");
  EXPECT_EQ(j["status"], "completed");
  EXPECT_LE(j["max_rel_error_vs_analytic"].get<double>(), 0.03);
  EXPECT_NEAR(j["centerline_velocity_m_s"].get<double>() / 0.045, 1.0, 1e-3);  // g W^2 / (8 nu)
  EXPECT_GT(j["mean_velocity_m_s"].get<double>(), 0.0);
}

TEST(ChannelFlowScene, FluxControlledCaseHoldsTargetMean) {
  const auto j = run_case_file("channel_flow_flux_control.toml", "flux");
  EXPECT_NEAR(j["mean_flux_z_m_s"].get<double>() / 0.03, 1.0, 1e-6);
  EXPECT_LE(j["max_rel_error_vs_analytic"].get<double>(), 0.03);
}

}  // namespace
}  // namespace boycott::scenes
