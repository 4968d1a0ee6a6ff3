// A scene added the way every scene is: this one file, declaring itself, and one line in its
// CMake list (tests/regression/scenes/CMakeLists.txt). It is not a scene of the product: it checks
// that a program linked as `boycott` is, plus a library of such files, knows and runs them all.
// free_fall: one sphere falling in vacuum from rest, v(t) = -g sin(theta) t, stepped at dt_dem.
#include <fmt/format.h>

#include "core/error.hpp"
#include "core/timers.hpp"
#include "scenes/run_common.hpp"
#include "scenes/scene.hpp"

namespace boycott::scenes {

namespace {

int run_free_fall(const CaseParams& p, RunContext& ctx) {
  RunClock clock;
  ModelTimers timers;
  const double g = p.gravity_vector()[2];  // along z, m/s^2
  double t = 0.0, v = 0.0;
  while (t < p.time.end_s - 1e-12) {
    v += g * p.time.dt_dem_s;
    t += p.time.dt_dem_s;
  }
  SummaryBase s;
  s.simulated_time_s = t;
  s.set_spent(clock.spent());
  s.mean_settling_velocity_m_s = v;
  auto j = make_summary(p, s, timers);
  j["analytic_velocity_m_s"] = g * t;
  write_file_atomic(ctx.out_dir / "summary.json", j.dump(2) + "\n");
  return kExitOk;
}

void free_fall_checks(const CaseParams& p, SceneFindings& f) {
  if (p.gravity.angle_deg == 0.0) f.errors.push_back("gravity.angle_deg = 0: nothing falls along z");
}

}  // namespace

const SceneRegistration kRegistered{{.name = "free_fall",
                                     .measures = "one sphere falling in vacuum (a test scene)",
                                     .reads = {"gravity.", "time.dt_dem", "time.end"},
                                     .has_particles = false,
                                     .fixed_particle_count = 1,
                                     .has_fluid = false,
                                     .own_checks = &free_fall_checks},
                                    &run_free_fall};

}  // namespace boycott::scenes
