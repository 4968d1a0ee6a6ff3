// The sediment_transport scene (issue 7) in a very short run: the flux controller holds the bulk
// velocity, the bed is poured to rest before the flow starts, the transport is downstream, and
// the summary's reference curves are the published ones at the measured Shields stress. The
// validation against Wong-Parker and Nielsen needs seconds of simulated time per bulk velocity:
// studies/validation_sediment_transport.toml (not part of the quick suite).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {
namespace {

using runs::run_case;

TEST(SedimentTransport, BulkVelocityHeldBedPouredAndTransportDownstream) {
  CaseParams p = parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/sediment_transport.toml");
  // A quarter of the reduced box in x and z (2000 particles), 20 ms of flow.
  for (const char* s : {"domain.length_x=0.005", "domain.height_z=0.01", "domain.cells=[5, 40, 10]",
                        "particles.count=2000", "time.end=0.02", "time.average_from=0.01"})
    apply_override(p, s);
  RunContext ctx;
  ctx.quiet = true;
  ctx.out_dir = std::filesystem::temp_directory_path() / "boycott_sediment_short";
  std::filesystem::remove_all(ctx.out_dir);
  ASSERT_EQ(run_case(p, ctx), 0);
  std::ifstream in(ctx.out_dir / "summary.json");
  const auto j = nlohmann::json::parse(in);
  const double tau = j["shields_stress"].get<double>(), q = j["q_star"].get<double>();
  std::printf("[ report ] 20 ms after the start: q* %.4g, tau* %.4g, bed height %.4g m, poured %.3g s\n", q,
              tau, j["bed_height_m"].get<double>(), j["bed_pouring_time_s"].get<double>());
  EXPECT_NEAR(j["mean_flux_z_m_s"].get<double>(), 0.8, 1e-6);
  EXPECT_LT(j["bed_pouring_time_s"].get<double>(), 2.0);  // the bed came to rest
  EXPECT_GT(q, 0.0);
  EXPECT_GT(tau, 0.0);
  EXPECT_GT(j["min_fluid_fraction"].get<double>(), 0.0);
  // Bed height from the particle volume at the packed fraction 0.6: 2000 spheres of 0.5 mm.
  const double vp = 2000.0 * M_PI / 6.0 * std::pow(0.5e-3, 3);
  EXPECT_NEAR(j["bed_height_m"].get<double>(), vp / (0.005 * 0.01 * 0.6), 1e-12);
  EXPECT_NEAR(j["q_star_wong_parker"].get<double>(), 3.97 * std::pow(tau - 0.0495, 1.5), 1e-12);
  EXPECT_NEAR(j["q_star_nielsen"].get<double>(), 12.0 * std::sqrt(tau) * (tau - 0.05), 1e-12);

  // profiles.csv: the flux density integrates over y to the mean transport rate, and the solid
  // fraction to the particle volume (over the plan area 0.005 x 0.01 m, rows 1 mm high).
  std::ifstream prof(ctx.out_dir / "profiles.csv");
  std::string line;
  std::getline(prof, line);
  EXPECT_EQ(line, "y_m,fluid_w_m_s,solid_fraction,particle_w_m_s,particle_flux_density_m_s");
  double q_sum = 0.0, solid = 0.0, y, w, a, wp, f;
  char c;
  int rows = 0;
  while (prof >> y >> c >> w >> c >> a >> c >> wp >> c >> f)
    q_sum += f * 1e-3, solid += a * 1e-3 * 0.005 * 0.01, ++rows;
  EXPECT_EQ(rows, 40);
  EXPECT_NEAR(q_sum, j["transport_rate_m2_s"].get<double>(), 1e-9 * std::abs(q_sum));
  EXPECT_NEAR(solid, vp, 1e-9 * vp);
}

TEST(SedimentTransport, StoppedAndResumedRunEqualsTheUninterruptedOneBitwise) {
  CaseParams p = parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/sediment_transport.toml");
  for (const char* s :
       {"domain.length_x=0.005", "domain.height_z=0.01", "domain.cells=[5, 40, 10]", "particles.count=2000",
        "time.end=0.01", "time.average_from=0.004", "time.checkpoint_every=1.0"})
    apply_override(p, s);
  auto summary = [](const std::filesystem::path& d) {
    std::ifstream in(d / "summary.json");
    return nlohmann::json::parse(in);
  };
  RunContext a;
  a.quiet = true;
  a.out_dir = std::filesystem::temp_directory_path() / "boycott_sediment_whole";
  std::filesystem::remove_all(a.out_dir);
  ASSERT_EQ(run_case(p, a), 0);

  std::atomic<bool> stop{false};
  RunContext b;
  b.quiet = true;
  b.out_dir = std::filesystem::temp_directory_path() / "boycott_sediment_resumed";
  std::filesystem::remove_all(b.out_dir);
  b.stop_requested = &stop;
  b.progress = [&](double t) {
    if (t >= 0.006) stop = true;
  };
  ASSERT_EQ(run_case(p, b), kExitInterrupted);
  stop = false;
  b.progress = nullptr;
  ASSERT_EQ(run_case(p, b), 0);
  const auto ja = summary(a.out_dir), jb = summary(b.out_dir);
  EXPECT_TRUE(jb["resumed_from_checkpoint"].get<bool>());
  for (const char* k : {"q_star", "q_star_stderr", "shields_stress", "mean_flux_z_m_s",
                        "mean_settling_velocity_m_s", "bed_pouring_time_s", "max_kinetic_energy_j"})
    EXPECT_EQ(ja[k].get<double>(), jb[k].get<double>()) << k;
  auto text = [](const std::filesystem::path& f) {
    std::ifstream in(f);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(text(a.out_dir / "profiles.csv"), text(b.out_dir / "profiles.csv"));  // its sums are checkpointed
  EXPECT_FALSE(text(a.out_dir / "profiles.csv").empty());
}

TEST(SedimentTransport, RefusesAnInclinedOrPeriodicChannel) {
  for (const char* bad : {"gravity.angle_deg=30.0", "domain.periodic_y=true"}) {
    CaseParams p =
        parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/sediment_transport.toml");
    apply_override(p, bad);
    RunContext ctx;
    ctx.quiet = true;
    ctx.out_dir = std::filesystem::temp_directory_path() / "boycott_sediment_bad";
    std::filesystem::remove_all(ctx.out_dir);
    EXPECT_THROW(run_case(p, ctx), InputError) << bad;
  }
}

}  // namespace
}  // namespace boycott::scenes
