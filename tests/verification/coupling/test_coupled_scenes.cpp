// The coupled scenes end to end, as `boycott case run` runs them, against the drag law, added-mass
// theory, the Ergun equation and the zero-slurry-velocity condition.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/case_params.hpp"
#include "runs/run_case.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {
namespace {

using runs::run_case;

nlohmann::json run_case_file(const std::string& file, const std::string& tag,
                             const std::vector<std::string>& sets = {}) {
  CaseParams p = parse_case_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/cases/" + file);
  for (const auto& s : sets) apply_override(p, s);
  RunContext ctx;
  ctx.quiet = true;
  ctx.out_dir = std::filesystem::temp_directory_path() / ("boycott_coupled_scene_" + tag);
  std::filesystem::remove_all(ctx.out_dir);
  EXPECT_EQ(run_case(p, ctx), 0);
  EXPECT_TRUE(std::filesystem::exists(ctx.out_dir / "timeseries.csv"));
  std::ifstream in(ctx.out_dir / "summary.json");
  return nlohmann::json::parse(in);
}

TEST(SingleParticle, TerminalVelocityWithinTwoPercentOfDragLawFromRe0p1To250) {
  // Cells 5 diameters wide (the particle's own momentum source barely moves the fluid at its
  // centre; see the next test for the trend), box 50 diameters across.
  struct Run {
    const char* mu;
    const char* end;
    const char* from;
  };
  for (const Run& r : {Run{"0.044", "0.05", "0.03"}, Run{"0.01", "0.1", "0.07"}, Run{"1.0e-3", "0.5", "0.3"},
                       Run{"3.5e-4", "0.5", "0.3"}}) {
    const auto j = run_case_file("single_particle.toml", std::string("re_") + r.mu,
                                 {std::string("fluid.viscosity=") + r.mu, std::string("time.end=") + r.end,
                                  std::string("time.average_from=") + r.from});
    const double err = j["rel_error"].get<double>();
    std::printf(
        "[ report ] single particle mu = %s Pa s: Re %.3g, w_t %.6g m/s vs %.6g (%+.2f %%), dx/d %.1f\n",
        r.mu, j["reynolds_number_reference"].get<double>(), j["terminal_velocity_m_s"].get<double>(),
        j["terminal_velocity_reference_m_s"].get<double>(), 100.0 * err,
        j["cell_size_over_diameter"].get<double>());
    EXPECT_LE(std::abs(err), 0.02) << "mu = " << r.mu;
  }
}

TEST(SingleParticle, SelfDisturbanceBiasFallsAsCellsGrowRelativeToTheParticle) {
  // At Re 1.6 the particle drags the fluid at its own position along with it (the slip it sees
  // is too small, so it settles too fast). 10 x 10 x 20 cells; the box scales with dx.
  double prev = 1e9;
  for (const char* spec : {"2", "3", "5", "8"}) {
    const double ratio = std::stod(spec), dx = ratio * 0.6e-3;
    std::ostringstream lx, lz;
    lx << "domain.length_x=" << 10 * dx;
    lz << "domain.height_z=" << 20 * dx;
    const auto j = run_case_file("single_particle.toml", std::string("dx_") + spec,
                                 {"fluid.viscosity=0.01", "time.end=0.1", "time.average_from=0.07", lx.str(),
                                  "domain.width_y=" + std::to_string(10 * dx), lz.str()});
    const double err = j["rel_error"].get<double>();
    std::printf("[ report ] single particle Re 1.6, dx/d = %s: error %+.2f %%\n", spec, 100.0 * err);
    EXPECT_LT(std::abs(err), prev + 1e-3);
    prev = std::abs(err);
  }
}

TEST(SingleParticle, AddedMassSetsTheStartAcceleration) {
  // Released from rest in still fluid, before drag acts: a = (rho_p - rho_f) g / (rho_p + rho_f/2);
  // without added mass (rho_p - rho_f) g / rho_p.
  for (const char* am : {"true", "false"}) {
    const auto j = run_case_file("single_particle.toml", std::string("am_") + am,
                                 {"forces.drag=\"none\"", std::string("forces.added_mass=") + am,
                                  "time.end=0.002", "time.average_from=0.0"});
    const double a = j["initial_acceleration_z_m_s2"].get<double>();
    const double rp = 2650.0, rf = 1000.0;
    const double expect = -(rp - rf) * 9.81 / (rp + (std::string(am) == "true" ? 0.5 * rf : 0.0));
    EXPECT_NEAR(a / expect, 1.0, 1e-4) << "added_mass = " << am;
  }
}

TEST(StiffDrag, TinyParticleInViscousFluidSettlesStablyToItsTerminalVelocity) {
  // d = 0.1 mm, rho_p 2650, mu = 1 Pa s: response time 1.5 us, dt_DEM = 10 us (spring limit
  // 12.5 us). Explicit drag would blow up; the implicit update must land on Stokes' velocity.
  // In creeping flow the particle's own momentum source raises the fluid velocity at its centre
  // by about 0.37 d/dx of its slip (measured: +7.3 % at dx/d = 5, +3.7 % at 10, +1.8 % at 20):
  // cells 20 diameters wide here.
  const auto j =
      run_case_file("single_particle.toml", "stiff",
                    {"particles.diameter=1.0e-4", "numerics.neighbor_skin=3.0e-5", "fluid.viscosity=1.0",
                     "time.dt_dem=1.0e-5", "domain.length_x=0.02", "domain.width_y=0.02",
                     "domain.height_z=0.04", "time.end=0.02", "time.average_from=0.01"});
  EXPECT_GT(j["dt_dem_over_response_time"].get<double>(), 5.0);
  EXPECT_LE(std::abs(j["rel_error"].get<double>()), 0.02);
  std::printf("[ report ] stiff drag: w_t %.5g m/s vs %.5g (%+.2f %%)\n",
              j["terminal_velocity_m_s"].get<double>(), j["terminal_velocity_reference_m_s"].get<double>(),
              100.0 * j["rel_error"].get<double>());
}

TEST(InclinedSettling, SmokeRunHoldsTheSlurryVelocityAtZero) {
  const auto j = run_case_file("inclined_settling_smoke.toml", "smoke");
  EXPECT_EQ(j["status"], "completed");
  EXPECT_LE(j["max_abs_slurry_velocity_m_s"].get<double>(), 1e-8);
  EXPECT_LT(j["mean_settling_velocity_m_s"].get<double>(), 0.0);
  // An error is always reported: from the autocorrelation where the window holds >= 20
  // correlation times of <w_p>, else from the window's two halves, with a warning that says so.
  const double windows = j["settling_velocity_window_correlation_times"].get<double>();
  EXPECT_GT(j["settling_velocity_correlation_time_s"].get<double>(), 0.0);
  EXPECT_TRUE(std::isfinite(j["settling_velocity_stderr_m_s"].get<double>()));
  EXPECT_TRUE(std::isfinite(j["settling_velocity_error_m_s"].get<double>()));
  if (windows < 20.0) {
    EXPECT_EQ(j["settling_velocity_error_method"], "two_halves");
    EXPECT_EQ(j["settling_velocity_error_dof"], 1.0);
    EXPECT_NE(j["warnings"].dump().find("two halves"), std::string::npos) << j["warnings"].dump();
  }
  EXPECT_GT(j["mean_fluid_velocity_m_s"].get<double>(), 0.0);  // the fluid goes up as particles go down
  EXPECT_TRUE(j["models"].contains("saffman_mei_lift"));       // the default lift law
  std::printf("[ report ] smoke: <<w_p>> = %.4g m/s +- %s, %.1f correlation times, max |slurry| %.2e m/s\n",
              j["mean_settling_velocity_m_s"].get<double>(), j["settling_velocity_stderr_m_s"].dump().c_str(),
              windows, j["max_abs_slurry_velocity_m_s"].get<double>());
}

TEST(Ergun, FrictionFactorWithinOnePercentFromRe1To1000) {
  const auto j = run_case_file("ergun.toml", "table1");
  EXPECT_NEAR(j["porosity"].get<double>(), 0.36, 0.005);
  double re_min = 1e30, re_max = 0.0;
  for (const auto& pt : j["points"]) {
    re_min = std::min(re_min, pt["re_star"].get<double>());
    re_max = std::max(re_max, pt["re_star"].get<double>());
    std::printf("[ report ] Ergun Re* %8.3f  f* %9.4f  Ergun %9.4f  error %+.3f %%\n",
                pt["re_star"].get<double>(), pt["f_star"].get<double>(), pt["f_star_ergun"].get<double>(),
                100.0 * pt["rel_error"].get<double>());
  }
  EXPECT_LE(re_min, 1.5);
  EXPECT_GE(re_max, 900.0);
  EXPECT_LE(j["max_rel_error_f_star"].get<double>(), 0.01);
  EXPECT_FALSE(j["models"].contains("dem_contacts"));  // frozen bed: contacts left out
}

}  // namespace
}  // namespace boycott::scenes
