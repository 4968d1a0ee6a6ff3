// A particle's own deposit must not push it sideways: one sphere held at its terminal slip in
// still fluid, anywhere across the 6-cell gap, drags the fluid with it (drag on both sides); the
// fluid forces it then reads back (drag, lift, pressure gradient, viscous, added mass) act along
// its slip. Measured after 30 fluid steps (30 ms, the disturbance spread over several cells); the
// transverse force is compared with the drag, for each sampling and lift law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/case_params.hpp"
#include "coupling/coupled_system.hpp"
#include "coupling/drag_laws.hpp"
#include "fluid/fluid_solver.hpp"

namespace boycott {
namespace {

constexpr double kW = 6.0e-3, kD = 0.6e-3;

struct OwnForce {
  double worst_ratio = 0.0;   ///< largest |F_y| / |F_drag,z| over the positions
  double at_y_mm = 0.0;       ///< where
  double signed_ratio = 0.0;  ///< F_y / |F_drag,z| there (+: toward the wall at y = W)
};

OwnForce own_transverse_force(const std::string& sampling, const std::string& lift) {
  OwnForce r;
  for (int m = 0; m < 9; ++m) {
    const double y = 0.5 * kD + (kW - kD) * m / 8.0;
    CaseParams p = parse_case_string(R"(
scene = "inclined_settling"
[fluid]
subgrid_model = "none"
[domain]
length_x = 0.008
width_y = 0.006
height_z = 0.008
cells = [8, 6, 8]
[particles]
count = 1
)");
    p.numerics.sampling = sampling;
    p.forces.lift = lift;
    validate(p);
    p.gravity.magnitude_m_s2 = 0.0;  // still fluid: only the particle's own deposit moves it
    const double vt = coupling::visit_drag_law(p.forces.drag, [&](const auto& law) {
      return coupling::terminal_slip_speed(law, 1.0, kD, 2650.0, 1000.0, 1e-3, 9.81);
    });
    coupling::CoupledSystem run(p, coupling::CoupledOptions{false, false});
    run.dem().add_particle(0, 4.3e-3, y, 4.1e-3, 0.5 * kD, 2650.0);
    run.start();
    run.fluid().set_target_mean_flux_z(kUnset);
    auto& s = run.dem().particles();
    s.vz[0] = -vt;  // held at its terminal slip (a frozen particle keeps its velocity)
    for (int k = 0; k < 30; ++k) run.step();
    run.coupler().prepare(run.dem(), run.fluid(), p.time.dt_cfd_s);
    const double fy = s.ext_y[0] + s.beta[0] * (s.ufy[0] - s.vy[0]);
    const double fz = s.beta[0] * (s.ufz[0] - s.vz[0]);
    const double ratio = std::abs(fy) / std::abs(fz);
    if (ratio > r.worst_ratio) r.worst_ratio = ratio, r.at_y_mm = y * 1e3, r.signed_ratio = fy / std::abs(fz);
  }
  return r;
}

TEST(OwnDeposit, AParticleHeldAtItsTerminalSlipIsNotPushedSidewaysByItsOwnDeposit) {
  // Below 1 % of the drag with Mei's lift (the default) or none, for both samplings. Saffman's
  // law, outside its validity at this Re_p, reads the particle's own wake next to a wall as shear
  // and pushes a particle that touches the wall into it by several per cent: printed, not asserted.
  for (const std::string sampling : {"kernel", "trilinear"})
    for (const std::string lift : {"saffman_mei", "saffman", "none"}) {
      const OwnForce f = own_transverse_force(sampling, lift);
      std::printf(
          "[ report ] %s sampling, lift %s: largest |F_y| / F_drag %.4f at y = %.2f mm (F_y / F_drag "
          "%+.4f)\n",
          sampling.c_str(), lift.c_str(), f.worst_ratio, f.at_y_mm, f.signed_ratio);
      if (lift != "saffman") {
        EXPECT_LT(f.worst_ratio, 0.01) << sampling << ", " << lift;
      }
    }
}

}  // namespace
}  // namespace boycott
