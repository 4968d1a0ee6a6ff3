// Fluid values read at particle centres next to the walls (numerics.sampling, issue 21):
// fields set analytically at their staggered nodes are read back at particles from y = d/2 to
// W - d/2. "trilinear" must read a field that is linear between its nodes and meets its wall rule
// exactly, plane Poiseuille within h^2 |u''| / 8, and a step in alpha_f within one cell; the
// first round's "kernel" sampling is measured beside it and must miss each bound (so each test
// can fail). Last, the momentum budget of a wall-bounded suspension closes with the wall shear,
// the time-level lag and the sampling mismatch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/case_params.hpp"
#include "coupling/coupled_system.hpp"
#include "coupling/coupler.hpp"
#include "coupling/drag_laws.hpp"
#include "fluid/fluid_solver.hpp"

namespace boycott {
namespace {

constexpr double kH = 1.0e-3, kW = 6.0e-3, kL = 8.0e-3, kD = 0.6e-3;

CaseParams channel_case(const std::string& sampling, const std::string& top_wall = "no_slip",
                        const std::string& drag = "none") {
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
[forces]
drag = "none"
pressure_gradient = false
viscous = false
added_mass = false
saffman_lift = false
)");
  p.numerics.sampling = sampling;
  p.domain.top_wall = top_wall;
  p.forces.drag = drag;
  validate(p);
  return p;
}

/// Particles on a line of y from d/2 to W - d/2 (n points), at x and z inside the nodes' span
/// (no periodic wrap, where a field linear in x or z would jump).
void add_line(coupling::CoupledSystem& run, int n) {
  for (int m = 0; m < n; ++m) {
    const double y = 0.5 * kD + (kW - kD) * m / (n - 1);
    const double x = kH * (0.6 + 6.3 * std::fmod(0.37 * m, 1.0));
    const double z = kH * (0.6 + 6.3 * std::fmod(0.61 * m + 0.2, 1.0));
    run.dem().add_particle(m, x, y, z, 0.5 * kD, 2650.0);
  }
}

/// Piecewise linear in y, 0 on both walls, 1 at the kink yk (a node of the field), or flat above
/// yk when `flat_top` (the slip wall's mirror rule).
double tent(double y, double yk, bool flat_top) {
  if (y <= yk) return y / yk;
  return flat_top ? 1.0 : (kW - y) / (kW - yk);
}

struct LinearResult {
  double max_err = 0.0, scale = 0.0;
};

LinearResult read_linear_fields(const std::string& sampling, bool slip_top) {
  const CaseParams p = channel_case(sampling, slip_top ? "slip" : "no_slip");
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, false});
  add_line(run, 41);
  run.start();
  // u and w: tangential, nodes at cell centres in y; kink at the centre node 2.5 h. v: wall
  // normal, nodes on the faces, 0 on the walls; kink at the face 3 h. Each times a linear
  // function of x and z.
  auto lin = [](double x, double z, double a, double b) { return 1.0 + a * x / kL + b * z / kL; };
  auto fu = [&](double x, double y, double z) {
    return 0.03 * tent(y, 2.5 * kH, slip_top) * lin(x, z, 0.7, -0.4);
  };
  auto fv = [&](double x, double y, double z) {
    return -0.02 * tent(y, 3.0 * kH, false) * lin(x, z, 0.3, 0.9);
  };
  auto fw = [&](double x, double y, double z) {
    return 0.05 * tent(y, 2.5 * kH, slip_top) * lin(x, z, -0.5, 0.6);
  };
  run.fluid().set_velocity(0, fu);
  run.fluid().set_velocity(1, fv);
  run.fluid().set_velocity(2, fw);
  run.coupler().prepare(run.dem(), run.fluid(), 0.0);
  const auto& s = run.dem().particles();
  LinearResult r;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const double x = s.x[i], y = s.y[i], z = s.z[i];
    const double want[3] = {fu(x, y, z), fv(x, y, z), fw(x, y, z)};
    const double got[3] = {s.ufx[i], s.ufy[i], s.ufz[i]};
    for (int c = 0; c < 3; ++c) {
      r.max_err = std::max(r.max_err, std::abs(got[c] - want[c]));
      r.scale = std::max(r.scale, std::abs(want[c]));
    }
  }
  return r;
}

TEST(SamplingAtWalls, LinearFieldsMeetingTheirWallRulesAreReadExactlyFromWallToWall) {
  for (bool slip_top : {false, true}) {
    const LinearResult tri = read_linear_fields("trilinear", slip_top);
    const LinearResult ker = read_linear_fields("kernel", slip_top);
    std::printf(
        "[ report ] linear fields, %s top wall: largest error trilinear %.3e, kernel %.3e m/s (scale %.3e)\n",
        slip_top ? "slip" : "no-slip", tri.max_err, ker.max_err, tri.scale);
    EXPECT_LE(tri.max_err, 1e-13 * tri.scale) << (slip_top ? "slip top" : "no-slip top");
    // The kernel's folded weights miss the wall rule: it must fail this bound.
    EXPECT_GT(ker.max_err, 1e-3 * ker.scale);
  }
}

struct PoiseuilleResult {
  double max_err_over_bound = 0.0;
  double ratio_at_wall = 0.0;  ///< read / true at y = d/2
};

PoiseuilleResult read_poiseuille(const std::string& sampling) {
  coupling::CoupledSystem run(channel_case(sampling), coupling::CoupledOptions{true, false});
  add_line(run, 61);
  run.start();
  const double wmax = 0.05;
  auto w = [&](double, double y, double) { return 4.0 * wmax * y * (kW - y) / (kW * kW); };
  run.fluid().set_velocity(2, w);
  run.coupler().prepare(run.dem(), run.fluid(), 0.0);
  const double bound = kH * kH * (8.0 * wmax / (kW * kW)) / 8.0;  // h^2 |w''| / 8
  const auto& s = run.dem().particles();
  PoiseuilleResult r;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const double want = w(0.0, s.y[i], 0.0);
    r.max_err_over_bound = std::max(r.max_err_over_bound, std::abs(s.ufz[i] - want) / bound);
    if (std::abs(s.y[i] - 0.5 * kD) < 1e-12) r.ratio_at_wall = s.ufz[i] / want;
  }
  return r;
}

TEST(SamplingAtWalls, PlanePoiseuilleIsReadWithinTheInterpolationBoundIncludingWallCells) {
  const PoiseuilleResult tri = read_poiseuille("trilinear"), ker = read_poiseuille("kernel");
  std::printf(
      "[ report ] plane Poiseuille over 6 cells: largest error / (h^2 |w''| / 8) trilinear %.3f, kernel "
      "%.3f; "
      "read / true at y = d/2: trilinear %.4f, kernel %.4f\n",
      tri.max_err_over_bound, ker.max_err_over_bound, tri.ratio_at_wall, ker.ratio_at_wall);
  EXPECT_LE(tri.max_err_over_bound, 1.0 + 1e-9);
  EXPECT_GT(ker.max_err_over_bound, 1.0);
}

struct StepResult {
  double smeared_beyond = 0.0;  ///< largest |beta - the side's value| / (beta_bed - beta_fluid) beyond h/2
};

StepResult read_alpha_step(const std::string& sampling) {
  // alpha_f = 0.5 below the face y_b = 2 h (a bed top), 1 above, set as the deposited solid
  // fraction; still fluid and particles at rest, so the drag coefficient of the paper's law is a
  // function of alpha_f alone (8.33 (1 - a)/a in the bed, a^-3.7 above).
  const CaseParams p = channel_case(sampling, "no_slip", "difelice_paper");
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, false});
  add_line(run, 61);
  run.start();
  const int nx = 8, ny = 6, nz = 8;
  const std::size_t cells = static_cast<std::size_t>(nx) * ny * nz;
  std::vector<std::vector<double>> st = {
      std::vector<double>(cells, 0.0),
      std::vector<double>(static_cast<std::size_t>(nx) * (ny + 1) * nz, 0.0),
      std::vector<double>(cells, 0.0),
      {0.0},
      std::vector<double>(cells, 0.0)};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < nx; ++i) st[4][(static_cast<std::size_t>(k) * ny + j) * nx + i] = 0.5;
  run.coupler().import_state(st, run.dem());
  run.coupler().prepare(run.dem(), run.fluid(), 0.0);
  const coupling::DragDiFelicePaper law;
  const double bed = law.beta(0.5, 0.0, kD, 1000.0, 1e-3), clear = law.beta(1.0, 0.0, kD, 1000.0, 1e-3);
  const double yb = 2.0 * kH;
  const auto& s = run.dem().particles();
  StepResult r;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    if (std::abs(s.y[i] - yb) < 0.5 * kH) continue;  // the one cell the step may take
    const double want = s.y[i] < yb ? bed : clear;
    r.smeared_beyond = std::max(r.smeared_beyond, std::abs(s.beta[i] - want) / (bed - clear));
  }
  return r;
}

TEST(SamplingAtWalls, AStepInFluidFractionIsNotSmearedBeyondOneCell) {
  const StepResult tri = read_alpha_step("trilinear"), ker = read_alpha_step("kernel");
  std::printf(
      "[ report ] alpha_f step at a bed top: largest departure of the drag coefficient more than h/2 from "
      "the "
      "step, as a fraction of the jump: trilinear %.3e, kernel %.3f\n",
      tri.smeared_beyond, ker.smeared_beyond);
  EXPECT_LE(tri.smeared_beyond, 1e-12);
  EXPECT_GT(ker.smeared_beyond, 0.01);
}

/// Momentum along z of a settling suspension between no-slip walls (gravity along z, tangential
/// to the walls): the change of fluid (BDF2 quantity) plus particle momentum equals gravity, the
/// driving gradient and the walls' shear, less the coupler's measured time-level lag and
/// sampling mismatch. Returns the residual over the force scale, and the mismatch's share.
struct BudgetResult {
  double residual_over_scale = 0.0, mismatch_over_change = 0.0, residual_without_mismatch = 0.0;
};

BudgetResult wall_bounded_budget(const std::string& sampling) {
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
count = 150
[gravity]
angle_deg = 90.0
[numerics]
simple_tolerance = 1e-10
simple_max_iterations = 200
)");
  p.numerics.sampling = sampling;
  validate(p);
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, true});
  const auto& b = run.dem().config().box;
  run.dem().insert_random(150, 0.3e-3, 2650.0, b.lo,
                          {b.lo[0] + b.len[0], b.lo[1] + b.len[1], b.lo[2] + b.len[2]}, 11);
  run.start();
  const int nx = 8, ny = 6, nz = 8;
  const double rho = 1000.0, nu = 1e-6, V = kL * kW * kL, g = -9.81, vcell = V / (nx * ny * nz);
  auto cell = [&](int i, int j, int k) { return i + nx * (j + ny * ((k + nz) % nz)); };
  auto fluid_momentum = [&] {
    const auto w = run.fluid().gather(2), a = run.fluid().gather(5);
    double m = 0.0;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
          m += rho * 0.5 * (a[cell(i, j, k)] + a[cell(i, j, k - 1)]) * w[cell(i, j, k)] * vcell;
    return m;
  };
  // The no-slip wall term of the fluid's viscous operator (momentum_assembly.cpp), -2 nu w / h_y^2
  // per unit mass on the w nodes next to each wall, at the new level. The fluid applies it times
  // alpha_f and the particles take the rest with their viscous force V_p div tau (set II), so the
  // whole system feels it without alpha_f.
  auto wall_force = [&] {
    const auto w = run.fluid().gather(2);
    const double hy = kW / ny;
    double f = 0.0;
    for (int k = 0; k < nz; ++k)
      for (int j : {0, ny - 1})
        for (int i = 0; i < nx; ++i) f -= rho * vcell * 2.0 * nu * w[cell(i, j, k)] / (hy * hy);
    return f;
  };
  auto particle_momentum = [&] {
    const auto& s = run.dem().particles();
    double m = 0.0;
    for (std::size_t i = 0; i < s.n_local; ++i) m += s.mass[i] * s.vz[i];
    return m;
  };
  double mp_total = 0.0;
  for (double m : run.dem().particles().mass) mp_total += m;
  const double vs = run.particle_volume_m3();
  std::vector<double> M{fluid_momentum()}, P{particle_momentum()}, ext{0.0}, lag{0.0}, mis{0.0};
  const int N = 30;
  double dt = 0.0;
  for (int n = 1; n <= N; ++n) {
    dt = run.step().dt_s;
    M.push_back(fluid_momentum());
    P.push_back(particle_momentum());
    const double G = run.fluid().mean_pressure_gradient_pa_m();
    ext.push_back(dt * (mp_total * g + rho * g * (V - vs) - G * V + wall_force()));
    lag.push_back(run.coupler().totals().lag_impulse_ns[2]);  // of step n-1, measured in step n
    mis.push_back(run.coupler().totals().sampling_mismatch_ns[2]);
  }
  run.coupler().prepare(run.dem(), run.fluid(), dt);
  lag.push_back(run.coupler().totals().lag_impulse_ns[2]);
  mis.push_back(run.coupler().totals().sampling_mismatch_ns[2]);
  auto Q = [&](int n) { return 1.5 * M[n] - 0.5 * M[n - 1]; };
  double impulse = 0.0, lag_sum = 0.0, mis_sum = 0.0, scale = 0.0;
  for (int n = 2; n <= N; ++n) {
    impulse += ext[n];
    lag_sum += lag[n + 1];
    mis_sum += mis[n + 1];
    scale += std::abs(ext[n]) + std::abs(P[n] - P[n - 1]);
  }
  const double change = (Q(N) - Q(1)) + (P[N] - P[1]);
  BudgetResult r;
  r.residual_over_scale = std::abs(change - (impulse - lag_sum - mis_sum)) / scale;
  r.residual_without_mismatch = std::abs(change - (impulse - lag_sum)) / scale;
  r.mismatch_over_change = std::abs(mis_sum / (P[N] - P[1]));
  std::printf(
      "[ report ] wall-bounded momentum budget, sampling %s, %d steps: residual %.2e of the force scale "
      "(%.2e without the mismatch term); mismatch %.2e of the particle momentum change\n",
      sampling.c_str(), N - 1, r.residual_over_scale, r.residual_without_mismatch, r.mismatch_over_change);
  return r;
}

TEST(SamplingAtWalls, MomentumBudgetOfAWallBoundedSuspensionCloses) {
  for (const char* sampling : {"kernel", "trilinear"}) {
    const BudgetResult r = wall_bounded_budget(sampling);
    EXPECT_LE(r.residual_over_scale, 1e-6) << sampling;
  }
}

}  // namespace
}  // namespace boycott

namespace boycott {
namespace {

/// The vorticity the lift reads at particles held at rest from d/2 to 5 d off the lower wall in a
/// shear flow w(y) set analytically: with every other force off and no drag, the lift is
/// F_y = 1.61 rho d^2 sqrt(nu / |w_x|) s_z w_x (s_z the sampled w, the other components 0), so the
/// test recovers w_x = sign(q) q^2 with q = F_y / (1.61 rho d^2 sqrt(nu) s_z) and compares it with
/// dw/dy. Returns the largest |read - exact| over the particles, over the largest |dw/dy| there
/// (Poiseuille's vorticity passes through 0 at the centreline, y = 5 d).
double vorticity_error(const std::string& sampling, const std::string& vorticity, bool poiseuille) {
  // The wall-sampling channel with only Saffman's lift on (Eq. 16, whose inversion is below).
  CaseParams p = channel_case(sampling);
  p.forces.saffman_lift = true;
  p.forces.lift = "saffman";
  p.numerics.vorticity = vorticity;
  validate(p);
  coupling::CoupledSystem run(p, coupling::CoupledOptions{true, false});
  const int n = 28;
  for (int m = 0; m < n; ++m) {
    const double y = kD * (0.5 + 4.5 * m / (n - 1));  // d/2 to 5 d
    const double x = kH * (0.6 + 6.3 * std::fmod(0.37 * m, 1.0));
    const double z = kH * (0.6 + 6.3 * std::fmod(0.61 * m + 0.2, 1.0));
    run.dem().add_particle(m, x, y, z, 0.5 * kD, 2650.0);
  }
  run.start();
  const double wmax = 0.05, gamma = 10.0;  // m/s, 1/s
  auto w = [&](double, double y, double) {
    return poiseuille ? 4.0 * wmax * y * (kW - y) / (kW * kW) : gamma * y;
  };
  auto dwdy = [&](double y) { return poiseuille ? 4.0 * wmax * (kW - 2.0 * y) / (kW * kW) : gamma; };
  run.fluid().set_velocity(2, w);
  run.coupler().prepare(run.dem(), run.fluid(), 0.0);
  const auto& s = run.dem().particles();
  const double rho = p.fluid.density_kg_m3, nu = p.fluid.viscosity_pa_s / rho;
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const double q = s.ext_y[i] / (1.61 * rho * kD * kD * std::sqrt(nu) * s.ufz[i]);
    const double read = (q < 0 ? -1.0 : 1.0) * q * q, exact = dwdy(s.y[i]);
    worst = std::max(worst, std::abs(read - exact));
    scale = std::max(scale, std::abs(exact));
  }
  return worst / scale;
}

TEST(SamplingAtWalls, TheLiftsVorticityNearAWallIsTheShearOfPoiseuilleAndCouette) {
  // Trilinear reading of the vorticity formed at the edges (with the wall edge one-sided) is
  // exact for a parabola and a linear shear from d/2 to 5 d; the cell-centred form's wall cell is
  // first order, and the kernel reading folds the wall: their errors are printed, not asserted.
  for (bool poiseuille : {true, false}) {
    const char* flow = poiseuille ? "Poiseuille" : "Couette";
    const double edges = vorticity_error("trilinear", "edges", poiseuille);
    const double centres = vorticity_error("trilinear", "cell_centres", poiseuille);
    const double kernel_edges = vorticity_error("kernel", "edges", poiseuille);
    const double kernel_centres = vorticity_error("kernel", "cell_centres", poiseuille);
    std::printf(
        "[ report ] %s, d/2 to 5 d off the wall, largest relative error of the lift's vorticity: trilinear "
        "edges %.2e, cell centres %.2e; kernel edges %.2e, cell centres %.2e\n",
        flow, edges, centres, kernel_edges, kernel_centres);
    EXPECT_LE(edges, 1e-9) << flow;
    EXPECT_LE(poiseuille ? 0.0 : centres, 1e-9) << flow;  // a linear shear: exact in both forms
  }
}

}  // namespace
}  // namespace boycott
