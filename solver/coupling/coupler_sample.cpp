// Coupler::prepare: the fluid sampled at every particle (kernel or trilinear weights) and the
// particle side of the coupling hook set from it: implicit drag, added mass, and the explicit
// pressure-gradient, viscous, lift and added-mass forces; the time-level lag and the sampling
// mismatch measured on the way (coupler.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include <mpi.h>

#include "core/constants.hpp"
#include "core/timers.hpp"
#include "coupling/coupler.hpp"
#include "coupling/drag_laws.hpp"
#include "coupling/drag_stability.hpp"
#include "coupling/stencil_sums.hpp"
#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::coupling {

/// What prepare reads from the face fields at one particle.
struct Coupler::FaceSample {
  double uf[3];                             ///< fluid velocity with the sampling's weights, m/s
  double fe[3] = {0.0, 0.0, 0.0};           ///< pressure-gradient and viscous force, N
  double dudt[3] = {0.0, 0.0, 0.0};         ///< Du/Dt, m/s^2
  double ufk[3], fek[3] = {0.0, 0.0, 0.0};  ///< read with the kernel's weights (trilinear: mismatch)
  double pg_y = 0.0, visc_y = 0.0;          ///< the force budget's split of fe[1]
};

[[gnu::always_inline]] inline void Coupler::sample_faces_kernel(const Stencil& st, double vp,
                                                                FaceSample& f) const {
  const double rho = s_.rho_f_kg_m3;
  for (int c = 0; c < 3; ++c) {
    const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
    const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
    const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
    // the face fields of component c share one layout: all four in one pass (a field whose force
    // is off is read and not used)
    const Offsets3 o = offsets(wx, wy, wz, fields_.velocity(c));
    const double* const fld[4] = {fields_.velocity(c).a.data(), fields_.pressure_gradient(c).a.data(),
                                  fields_.viscous(c).a.data(), fields_.material_derivative(c).a.data()};
    double v[4];
    sample_fields(o, fld, v);
    f.uf[c] = v[0];
    if (s_.pressure_gradient) f.fe[c] -= vp * v[1];
    if (s_.viscous) f.fe[c] += rho * vp * v[2];
    if (s_.added_mass) f.dudt[c] = v[3];
    if (c == 1 && budget_) {
      f.pg_y = s_.pressure_gradient ? -vp * v[1] : 0.0;
      f.visc_y = s_.viscous ? rho * vp * v[2] : 0.0;
    }
  }
}

[[gnu::always_inline]] inline void Coupler::sample_faces_trilinear(const Stencil& st, const LinearStencil& ls,
                                                                   double vp, FaceSample& f) const {
  const double rho = s_.rho_f_kg_m3;
  for (int c = 0; c < 3; ++c) {
    const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
    const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
    const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
    const GridField& u = fields_.velocity(c);
    const Offsets3 o = offsets(wx, wy, wz, u);  // the kernel's, for the mismatch
    const Weights1D& lx = ls.x[c == 0 ? 1 : 0];
    const Weights1D& lz = ls.z[c == 2 ? 1 : 0];
    const Offsets3 ou = offsets(lx, c == 1 ? ls.y_normal : ls.y_tangential, lz, u);
    const Offsets3 og = offsets(lx, c == 1 ? ls.y_face_extrapolated : ls.y_centre_extrapolated, lz, u);
    f.uf[c] = sample(ou, u.a);
    f.ufk[c] = sample(o, u.a);
    if (s_.pressure_gradient) {
      f.fe[c] -= vp * sample(og, fields_.pressure_gradient(c).a);
      f.fek[c] -= vp * sample(o, fields_.pressure_gradient(c).a);
      if (c == 1) f.pg_y = f.fe[c];
    }
    if (s_.viscous) {
      const double fv = rho * vp * sample(og, fields_.viscous(c).a);
      f.fe[c] += fv;
      f.fek[c] += rho * vp * sample(o, fields_.viscous(c).a);
      if (c == 1) f.visc_y = fv;
    }
    if (s_.added_mass) f.dudt[c] = sample(og, fields_.material_derivative(c).a);
  }
}

[[gnu::always_inline]] inline double Coupler::sample_solid_and_vorticity(const Stencil& st,
                                                                         const LinearStencil& ls, bool linear,
                                                                         double (&w)[3]) const {
  const Offsets3 oc = linear ? offsets(ls.x[0], ls.y_centre_extrapolated, ls.z[0], solid_)
                             : offsets(st.cell[0], st.cell[1], st.cell[2], solid_);  // cell-centred fields
  const bool lift = s_.lift != LiftLaw::none;
  if (s_.edge_vorticity) {
    // Each component from its own edges (fluid_fields.hpp), with the weights of its location.
    const double solid =
        linear ? sample(offsets(ls.x[0], ls.y_alpha, ls.z[0], solid_), solid_.a) : sample(oc, solid_.a);
    if (lift && linear) {
      w[0] = sample(offsets(ls.x[0], ls.y_normal, ls.z[1], fields_.vorticity(0)), fields_.vorticity(0).a);
      w[1] = sample(offsets(ls.x[1], ls.y_tangential, ls.z[1], fields_.vorticity(1)), fields_.vorticity(1).a);
      w[2] = sample(offsets(ls.x[1], ls.y_normal, ls.z[0], fields_.vorticity(2)), fields_.vorticity(2).a);
    } else if (lift) {
      w[0] =
          sample(offsets(st.cell[0], st.face[1], st.face[2], fields_.vorticity(0)), fields_.vorticity(0).a);
      w[1] =
          sample(offsets(st.face[0], st.cell[1], st.face[2], fields_.vorticity(1)), fields_.vorticity(1).a);
      w[2] =
          sample(offsets(st.face[0], st.face[1], st.cell[2], fields_.vorticity(2)), fields_.vorticity(2).a);
    }
    return solid;
  }
  if (!linear) {
    // the vorticity (cell-centred, like the solid fraction) in the solid fraction's pass, read
    // whether or not the lift uses it
    const double* const f[4] = {solid_.a.data(), fields_.vorticity(0).a.data(), fields_.vorticity(1).a.data(),
                                fields_.vorticity(2).a.data()};
    double v[4];
    sample_fields(oc, f, v);
    w[0] = v[1], w[1] = v[2], w[2] = v[3];
    return v[0];
  }
  const double solid = sample(offsets(ls.x[0], ls.y_alpha, ls.z[0], solid_), solid_.a);
  if (lift)
    for (int c = 0; c < 3; ++c) w[c] = sample(oc, fields_.vorticity(c).a);
  return solid;
}

namespace {

/// Time-level lag (see coupler.hpp): what the fluid gave at level n+1 minus what the particle
/// received at level n over the last sub-cycle, both with these weights, into lag (N s). Measured,
/// not fed back: handing it to the fluid as an explicit source undoes the implicit drag (a frozen
/// dense bed diverges) and feeds pressure jumps back in dense beds. Keeps this sampling's
/// force for the next one and resets the drag impulse.
[[gnu::always_inline]] inline void record_lag(particles::ParticleStore& p, std::size_t i,
                                              const double (&uf)[3], const double (&fe)[3], double dt_prev,
                                              std::vector<double>& lag) {
  const double ufo[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
  double* fpv[3] = {&p.fpv_x[i], &p.fpv_y[i], &p.fpv_z[i]};
  for (int c = 0; c < 3; ++c) {
    lag[c] += dt_prev * (p.beta[i] * (uf[c] - ufo[c]) + (fe[c] - *fpv[c]));
    *fpv[c] = fe[c];
  }
  p.drag_jx[i] = p.drag_jy[i] = p.drag_jz[i] = 0.0;
}

}  // namespace

[[gnu::always_inline]] inline void Coupler::add_explicit_forces(particles::ParticleStore& p, std::size_t i,
                                                                const double (&slip)[3], const double (&w)[3],
                                                                double d, double vp, const FaceSample& f,
                                                                double (&fe)[3], double (&react)[3],
                                                                double (&fl)[3]) const {
  const double rho = s_.rho_f_kg_m3, nu = s_.mu_pa_s / rho;
  if (s_.lift != LiftLaw::none) {
    lift_force(s_.lift, slip, w, d, rho, nu, fl);
    for (int c = 0; c < 3; ++c) fe[c] += fl[c], react[c] -= fl[c];
  }
  if (s_.added_mass) {
    // Eq. 17, with the particle's own acceleration moved into its mass matrix (madd): the
    // explicit part is (rho V_p / 2) Du_f/Dt.
    const double ma = 0.5 * rho * vp;
    p.madd[i] = ma;
    for (int c = 0; c < 3; ++c) fe[c] += ma * f.dudt[c], react[c] -= ma * f.dudt[c];
  } else {
    p.madd[i] = 0.0;
  }
  p.ext_x[i] = fe[0], p.ext_y[i] = fe[1], p.ext_z[i] = fe[2];
}

[[gnu::always_inline]] inline void Coupler::add_to_budget(double y, const double (&fl)[3],
                                                          const FaceSample& f, double madd, double slip,
                                                          const double (&w)[3], double d) const {
  const double nu = s_.mu_pa_s / s_.rho_f_kg_m3;
  budget_->add_prepared(ForceBudget::lift, y, fl[1]);
  budget_->add_prepared(ForceBudget::pressure_gradient, y, f.pg_y);
  budget_->add_prepared(ForceBudget::viscous, y, f.visc_y);
  budget_->add_prepared(ForceBudget::added_mass, y, madd * f.dudt[1]);
  budget_->add_prepared(ForceBudget::re_p, y, slip * d / nu);
  budget_->add_prepared(ForceBudget::re_w, y,
                        std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * d * d / nu);
}

template <class Law>
void Coupler::prepare_impl(const Law& law, particles::DemSystem& dem, double dt_prev) {
  auto& p = dem.particles();
  const double rho = s_.rho_f_kg_m3, mu = s_.mu_pa_s;
  const auto& lo = dem.config().box.lo;
  const bool linear = s_.sampling == Sampling::trilinear;
  std::vector<double> lag(3, 0.0);       // this rank's share of totals_.lag_impulse_ns
  std::vector<double> mismatch(3, 0.0);  // and of totals_.sampling_mismatch_ns
  double stable_dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const double px = p.x[i] - lo[0], py = p.y[i] - lo[1], pz = p.z[i] - lo[2];
    const Stencil st = stencil(px, py, pz);
    const double d = 2.0 * p.radius[i];
    const double vp = kPi * d * d * d / 6.0;
    LinearStencil ls;
    FaceSample f;
    if (linear) {
      ls = linear_stencil(px, py, pz, st.z_image);
      sample_faces_trilinear(st, ls, vp, f);
      for (int c = 0; c < 3; ++c)
        mismatch[c] += dt_prev * (p.beta[i] * (f.ufk[c] - f.uf[c]) + (f.fek[c] - f.fe[c]));
    } else {
      sample_faces_kernel(st, vp, f);
    }
    record_lag(p, i, f.uf, f.fe, dt_prev, lag);
    double w[3] = {0.0, 0.0, 0.0};
    const double alpha_f = 1.0 - sample_solid_and_vorticity(st, ls, linear, w);
    const double slip_v[3] = {f.uf[0] - p.vx[i], f.uf[1] - p.vy[i], f.uf[2] - p.vz[i]};
    const double slip = std::sqrt(slip_v[0] * slip_v[0] + slip_v[1] * slip_v[1] + slip_v[2] * slip_v[2]);
    p.beta[i] = law.beta(alpha_f, slip, d, rho, mu);
    p.ufx[i] = f.uf[0], p.ufy[i] = f.uf[1], p.ufz[i] = f.uf[2];
    double fe[3] = {f.fe[0], f.fe[1], f.fe[2]}, react[3] = {0.0, 0.0, 0.0}, fl[3] = {0.0, 0.0, 0.0};
    add_explicit_forces(p, i, slip_v, w, d, vp, f, fe, react, fl);
    if (s_.drag_dt_limit)
      stable_dt = std::min(stable_dt, drag_stable_dt_s(alpha_f, (p.mass[i] + p.madd[i]) / p.beta[i]));
    if (budget_) add_to_budget(p.y[i], fl, f, p.madd[i], slip, w, d);
    p.v0x[i] = p.vx[i], p.v0y[i] = p.vy[i], p.v0z[i] = p.vz[i];
    p.react_x[i] = react[0], p.react_y[i] = react[1], p.react_z[i] = react[2];
  }
  if (window_) lag = particles::ordered_sum(window_->comm(), lag);
  for (int c = 0; c < 3; ++c) totals_.lag_impulse_ns[c] = lag[c];
  if (linear && window_) mismatch = particles::ordered_sum(window_->comm(), mismatch);
  for (int c = 0; c < 3; ++c) totals_.sampling_mismatch_ns[c] = mismatch[c];
  // A minimum is exact whatever the order, so every rank count gets the same step.
  if (window_) MPI_Allreduce(MPI_IN_PLACE, &stable_dt, 1, MPI_DOUBLE, MPI_MIN, window_->comm());
  totals_.drag_stable_dt_s = stable_dt;
}

void Coupler::prepare(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_prev_s) {
  const auto t0 = std::chrono::steady_clock::now();
  fields_.update(fs, dt_prev_s, s_.viscous, s_.added_mass, s_.lift != LiftLaw::none);
  totals_.lag_impulse_ns = {0.0, 0.0, 0.0};
  totals_.sampling_mismatch_ns = {0.0, 0.0, 0.0};
  visit_drag_law(s_.drag, [&](const auto& law) { prepare_impl(law, dem, dt_prev_s); });
  seconds_sample += seconds_since(t0);
}

}  // namespace boycott::coupling
