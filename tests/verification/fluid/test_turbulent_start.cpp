// The turbulent start (fluid/turbulent_start.hpp) against the impulsive start from rest, in the
// sediment_transport scene's channel without its bed: 10 x 40 x 20 mm (x, y, z) on 1 mm cells, a
// no-slip wall at y = 0, a slip top, periodic x and z, water, Vreman on, the flux controller
// holding a bulk velocity U = 0.8 m/s (Re = U H / nu = 32 000). The wall stress is exact from the
// controller's gradient: the flux is held, so the driving force on the column, -G H per unit wall
// area, is the wall stress.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "fluid/fluid_solver.hpp"
#include "fluid/turbulent_start.hpp"

namespace {

using boycott::fluid::FluidSettings;
using boycott::fluid::FluidSolver;

constexpr double kU = 0.8, kH = 0.04, kNu = 1.0e-6, kRho = 1000.0, kEnd = 1.0;  // m/s, m, m^2/s, kg/m^3, s

FluidSettings channel() {
  FluidSettings s;
  s.grid.n = {10, 40, 20};
  s.grid.length_m = {0.01, kH, 0.02};
  s.grid.periodic = {true, false, true};
  s.vreman = true;
  s.top_slip = true;
  s.dt_max_s = 0.5e-3;
  s.target_mean_flux_z_m_s = kU;
  return s;
}

struct History {
  std::vector<double> t, wall_stress;  // s, Pa
  double u_rms_end = 0.0;              // rms of u (x) over the faces at the end, m/s
};

History run(FluidSolver& f) {
  History h;
  while (f.time_s() < kEnd - 1e-12) {
    f.step(std::min(f.stable_dt(), kEnd - f.time_s()));
    h.t.push_back(f.time_s());
    h.wall_stress.push_back(-f.mean_pressure_gradient_pa_m() * kH);
  }
  double s = 0.0;
  const auto u = f.gather(0);
  for (double v : u) s += v * v;
  h.u_rms_end = std::sqrt(s / static_cast<double>(u.size()));
  return h;
}

}  // namespace

TEST(TurbulentStart, FromRestTheFlowStaysAStokesLayer) {
  // Stokes' first problem: tau_w = mu U / sqrt(pi nu t), while the layer (sqrt(nu t) = 1 mm at
  // 1 s) is thin against H. With one cell across the layer the grid overstates it: +13 % at 1 s
  // was measured; 25 % allowed. No velocity across the flow appears: it stays laminar, and its
  // wall stress keeps falling instead of reaching the turbulent value (next test).
  FluidSolver rest(channel());
  const History a = run(rest);
  const double stokes = kRho * kNu * kU / std::sqrt(M_PI * kNu * a.t.back());
  std::printf("wall stress at %.3f s: %.4f Pa, Stokes layer %.4f Pa; rms u %.3g m/s\n", a.t.back(),
              a.wall_stress.back(), stokes, a.u_rms_end);
  EXPECT_NEAR(a.wall_stress.back(), stokes, 0.25 * stokes);
  EXPECT_LT(a.u_rms_end, 1e-6 * kU);
}

TEST(TurbulentStart, ReachesDeansWallStress) {
  // Dean's (1978) smooth-channel correlation C_f = 0.073 Re_m^-1/4 with Re_m = 2 H U / nu (the
  // slip top is the half-channel's centre plane) gives 1.47 Pa. The 1 mm grid puts the first u
  // node ~20 wall units out, where an LES wall stress is uncertain by tens of per cent: a
  // factor 1.5 is allowed (1.6-1.75 Pa was measured over 1-3 s on 10 x 20 and 20 x 40 mm plans).
  // The fluctuations must persist (the start's own are ~3.5 % of U).
  FluidSolver turbulent(channel());
  boycott::fluid::TurbulentStartSettings ts;
  ts.bulk_velocity_m_s = kU;
  ts.roughness_m =
      1.1e-4;  // smooth wall: k_s = 30 z0 with the smooth log law's z0 = nu / (9 u*), u* ~ 0.03 m/s
  boycott::fluid::start_turbulent_channel(turbulent, ts);
  const History b = run(turbulent);
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < b.t.size(); ++k)
    if (b.t[k] > 0.5) sum += b.wall_stress[k], ++n;
  const double mean_stress = sum / n;
  const double dean = 0.5 * kRho * kU * kU * 0.073 * std::pow(2.0 * kH * kU / kNu, -0.25);
  std::printf("mean wall stress over 0.5-%.2f s: %.4f Pa, Dean %.4f Pa; rms u at the end %.4f m/s\n",
              b.t.back(), mean_stress, dean, b.u_rms_end);
  EXPECT_GT(mean_stress, dean / 1.5);
  EXPECT_LT(mean_stress, dean * 1.5);
  EXPECT_GT(b.u_rms_end, 0.01 * kU);
}
