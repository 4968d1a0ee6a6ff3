#include "coupling/coupler.hpp"

#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "coupling/drag_laws.hpp"
#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::coupling {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

CouplingSettings CouplingSettings::from_case(const CaseParams& p) {
  CouplingSettings s;
  s.drag = p.forces.drag;
  s.saffman_lift = p.forces.saffman_lift;
  s.added_mass = p.forces.added_mass;
  s.pressure_gradient = p.forces.pressure_gradient;
  s.viscous = p.forces.viscous;
  s.kernel = kernel_from_name(p.numerics.void_fraction_kernel);
  s.rho_f_kg_m3 = p.fluid.density_kg_m3;
  s.mu_pa_s = p.fluid.viscosity_pa_s;
  s.top_slip = p.domain.top_wall == "slip";
  return s;
}

Coupler::Coupler(const CouplingSettings& s, const GridSpec& g) : s_(s), g_(g), fields_(g, s.top_slip) {
  const bool per[3] = {g.periodic[0], g.periodic[1], g.periodic[2]};
  const int nx = (int)g.n[0], ny = (int)g.n[1], nz = (int)g.n[2];
  solid_.resize(nx, ny, nz, per);
  for (int c = 0; c < 3; ++c) {
    const int nyc = (c == 1 && !g.periodic[1]) ? ny + 1 : ny;
    for (GridField* f : {&K_[c], &KU_[c], &S_[c]}) f->resize(nx, nyc, nz, per);
  }
}

Coupler::Stencil Coupler::stencil(double x, double y, double z) const {
  Stencil st;
  const double pos[3] = {x, y, z};
  for (int d = 0; d < 3; ++d) {
    st.cell[d] = cell_weights(s_.kernel, pos[d], g_.dx(d), (int)g_.n[d], !g_.periodic[d]);
    st.face[d] = face_weights(st.cell[d]);
  }
  return st;
}

std::size_t Coupler::slot(std::int64_t id) {
  if (id < 0) throw PhysicsError(fmt::format("negative particle id {}", id));
  const auto k = static_cast<std::size_t>(id);
  if (k >= v0_[0].size())
    for (int c = 0; c < 3; ++c) {
      v0_[c].resize(k + 1, 0.0);
      react_[c].resize(k + 1, 0.0);
      fpv_[c].resize(k + 1, 0.0);
      owed_[c].resize(k + 1, 0.0);
    }
  return k;
}

namespace {

/// A particle's separable stencil on one grid array with the periodic wrap and the strides applied
/// once. GridField::index wraps each point with integer divisions, which made sampling ~27 % of a
/// coupled step of the reduced base case; the sums below keep its order (x inside y inside z), so
/// results are unchanged to the bit.
struct Offsets3 {
  int n[3];
  std::size_t off[3][4];  // offset of point a along d into the array (stride included)
  double w[3][4];
};

inline Offsets3 offsets(const Weights1D& wx, const Weights1D& wy, const Weights1D& wz, const GridField& f) {
  Offsets3 o{};
  const Weights1D* W[3] = {&wx, &wy, &wz};
  const int dim[3] = {f.nx, f.ny, f.nz};
  const std::size_t stride[3] = {1, static_cast<std::size_t>(f.nx), static_cast<std::size_t>(f.nx) * f.ny};
  for (int d = 0; d < 3; ++d) {
    o.n[d] = W[d]->n;
    for (int a = 0; a < W[d]->n; ++a) {
      const int i = f.periodic[d] ? GridField::wrap(W[d]->first + a, dim[d]) : W[d]->first + a;
      o.off[d][a] = static_cast<std::size_t>(i) * stride[d];
      o.w[d][a] = W[d]->w[a];
    }
  }
  return o;
}

/// Sum over the stencil of w_x(i) w_y(j) w_z(k) f(i,j,k).
inline double sample(const Offsets3& o, const std::vector<double>& field) {
  const double* f = field.data();
  double s = 0.0;
  for (int c = 0; c < o.n[2]; ++c) {
    double sy = 0.0;
    for (int b = 0; b < o.n[1]; ++b) {
      const double* row = f + o.off[2][c] + o.off[1][b];
      double sx = 0.0;
      for (int a = 0; a < o.n[0]; ++a) sx += o.w[0][a] * row[o.off[0][a]];
      sy += o.w[1][b] * sx;
    }
    s += o.w[2][c] * sy;
  }
  return s;
}

/// Calls f(index, w_x w_y w_z) for every stencil point.
template <class F>
inline void scatter(const Offsets3& o, F&& f) {
  for (int c = 0; c < o.n[2]; ++c)
    for (int b = 0; b < o.n[1]; ++b)
      for (int a = 0; a < o.n[0]; ++a) f(o.off[2][c] + o.off[1][b] + o.off[0][a], o.w[0][a] * o.w[1][b] * o.w[2][c]);
}

}  // namespace

template <class Law>
void Coupler::prepare_impl(const Law& law, particles::DemSystem& dem, double dt_prev) {
  auto& p = dem.particles();
  const double rho = s_.rho_f_kg_m3, mu = s_.mu_pa_s, nu = mu / rho;
  const auto& lo = dem.config().box.lo;
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const Stencil st = stencil(p.x[i] - lo[0], p.y[i] - lo[1], p.z[i] - lo[2]);
    const double d = 2.0 * p.radius[i];
    const double vp = kPi * d * d * d / 6.0;
    double uf[3], fe[3] = {0.0, 0.0, 0.0}, dudt[3] = {0.0, 0.0, 0.0};
    for (int c = 0; c < 3; ++c) {
      const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
      const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
      const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
      // the face fields of component c share one layout
      const Offsets3 o = offsets(wx, wy, wz, fields_.velocity(c));
      uf[c] = sample(o, fields_.velocity(c).a);
      if (s_.pressure_gradient) fe[c] -= vp * sample(o, fields_.pressure_gradient(c).a);
      if (s_.viscous) fe[c] += rho * vp * sample(o, fields_.viscous(c).a);
      if (s_.added_mass) dudt[c] = sample(o, fields_.material_derivative(c).a);
    }
    // Time-level lag (see coupler.hpp): what the fluid gave at level n+1 minus what the particle
    // received at level n over the last sub-cycle, both with these weights. Measured, not fed
    // back: handing it to the fluid as an explicit source undoes the implicit drag (a frozen
    // dense bed diverges) and feeds pressure jumps back in dense beds.
    const std::size_t k = slot(p.id[i]);
    {
      const double ufo[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
      for (int c = 0; c < 3; ++c) {
        owed_[c][k] = dt_prev * (p.beta[i] * (uf[c] - ufo[c]) + (fe[c] - fpv_[c][k]));
        totals_.lag_impulse_ns[c] += owed_[c][k];
        fpv_[c][k] = fe[c];
      }
      p.drag_jx[i] = p.drag_jy[i] = p.drag_jz[i] = 0.0;
    }
    const Offsets3 oc = offsets(st.cell[0], st.cell[1], st.cell[2], solid_);  // cell-centred fields
    const double solid = sample(oc, solid_.a);
    const double alpha_f = 1.0 - solid;
    const double s0 = uf[0] - p.vx[i], s1 = uf[1] - p.vy[i], s2 = uf[2] - p.vz[i];
    const double slip = std::sqrt(s0 * s0 + s1 * s1 + s2 * s2);
    p.beta[i] = law.beta(alpha_f, slip, d, rho, mu);
    p.ufx[i] = uf[0], p.ufy[i] = uf[1], p.ufz[i] = uf[2];

    double react[3] = {0.0, 0.0, 0.0};
    if (s_.saffman_lift) {
      double w[3];
      for (int c = 0; c < 3; ++c) {
        const GridField& W = fields_.vorticity(c);
        w[c] = sample(oc, W.a);
      }
      const double wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      if (wn > 0.0) {
        // Eq. 16: 1.61 rho d^2 sqrt(nu / |w|) (u_f - u_p) x w
        const double cst = 1.61 * rho * d * d * std::sqrt(nu / wn);
        const double fl[3] = {cst * (s1 * w[2] - s2 * w[1]), cst * (s2 * w[0] - s0 * w[2]), cst * (s0 * w[1] - s1 * w[0])};
        for (int c = 0; c < 3; ++c) fe[c] += fl[c], react[c] -= fl[c];
      }
    }
    if (s_.added_mass) {
      // Eq. 17, with the particle's own acceleration moved into its mass matrix (madd): the
      // explicit part is (rho V_p / 2) Du_f/Dt.
      const double ma = 0.5 * rho * vp;
      p.madd[i] = ma;
      for (int c = 0; c < 3; ++c) fe[c] += ma * dudt[c], react[c] -= ma * dudt[c];
    } else {
      p.madd[i] = 0.0;
    }
    p.ext_x[i] = fe[0], p.ext_y[i] = fe[1], p.ext_z[i] = fe[2];

    v0_[0][k] = p.vx[i], v0_[1][k] = p.vy[i], v0_[2][k] = p.vz[i];
    for (int c = 0; c < 3; ++c) react_[c][k] = react[c];
  }
}

std::vector<std::vector<double>> Coupler::export_state() const {
  auto st = fields_.export_state();
  for (int c = 0; c < 3; ++c) st.push_back(fpv_[c]);
  st.push_back(solid_.a);
  return st;
}

void Coupler::import_state(const std::vector<std::vector<double>>& st) {
  if (st.size() != 8) throw CheckpointError("coupling state: expected 8 arrays");
  if (st[7].size() != solid_.a.size()) throw CheckpointError("coupling state: solid fraction of another grid");
  solid_.a = st[7];
  fields_.import_state({st.begin(), st.begin() + 4});
  for (int c = 0; c < 3; ++c) {
    fpv_[c] = st[4 + c];
    const std::size_t n = fpv_[c].size();
    v0_[c].resize(n, 0.0);
    react_[c].resize(n, 0.0);
    owed_[c].resize(n, 0.0);
  }
}

void Coupler::prepare(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_prev_s) {
  const auto t0 = Clock::now();
  fields_.update(fs, dt_prev_s, s_.viscous, s_.added_mass, s_.saffman_lift);
  totals_.lag_impulse_ns = {0.0, 0.0, 0.0};
  visit_drag_law(s_.drag, [&](const auto& law) { prepare_impl(law, dem, dt_prev_s); });
  seconds_sample += since(t0);
}

void Coupler::deposit(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_s) {
  const auto t0 = Clock::now();
  auto& p = dem.particles();
  const double vcell = g_.cell_volume_m3();
  const auto& lo = dem.config().box.lo;
  std::fill(solid_.a.begin(), solid_.a.end(), 0.0);
  for (int c = 0; c < 3; ++c)
    for (GridField* f : {&K_[c], &KU_[c], &S_[c]}) std::fill(f->a.begin(), f->a.end(), 0.0);
  const bool forces = dt_s > 0.0;
  const auto lag = totals_.lag_impulse_ns;
  totals_ = ExchangeTotals{};
  totals_.lag_impulse_ns = lag;
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const Stencil st = stencil(p.x[i] - lo[0], p.y[i] - lo[1], p.z[i] - lo[2]);
    const double r = p.radius[i];
    const double frac = (4.0 / 3.0) * kPi * r * r * r / vcell;
    scatter(offsets(st.cell[0], st.cell[1], st.cell[2], solid_), [&](std::size_t q, double w) { solid_.a[q] += w * frac; });
    if (!forces) continue;
    const std::size_t s = slot(p.id[i]);
    // The fluid's drag is K (u_p - u) with K u_p = beta u_f(n) - J / dt: with u at level n it
    // returns exactly the impulse J the kicks applied. The reaction to the explicit forces uses
    // the particle's actual velocity change (added mass).
    const double vs[3] = {p.vx[i], p.vy[i], p.vz[i]};
    const double J[3] = {p.drag_jx[i], p.drag_jy[i], p.drag_jz[i]};
    const double uf[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
    double rf[3];
    for (int c = 0; c < 3; ++c) {
      rf[c] = react_[c][s];
      if (s_.added_mass) rf[c] += 0.5 * s_.rho_f_kg_m3 * (4.0 / 3.0) * kPi * r * r * r * (vs[c] - v0_[c][s]) / dt_s;
      totals_.reaction_n[c] += rf[c];
    }
    const double b = p.beta[i];
    for (int c = 0; c < 3; ++c) {
      const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
      const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
      const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
      const double kb = b / vcell, kub = (b * uf[c] - J[c] / dt_s) / vcell, sr = rf[c] / vcell;
      scatter(offsets(wx, wy, wz, K_[c]), [&](std::size_t q, double w) {
        K_[c].a[q] += w * kb;
        KU_[c].a[q] += w * kub;
        S_[c].a[q] += w * sr;
      });
    }
  }
  for (double v : solid_.a) totals_.solid_volume_m3 += v * vcell;

  // Into the fluid's deposition arrays (one rank: owned = whole grid). The y-wall rows of v are
  // not fluid unknowns: the share deposited there goes into the wall.
  const int nx = (int)g_.n[0], ny = (int)g_.n[1], nz = (int)g_.n[2];
  fs.begin_deposition();
  PetscScalar*** sol = fs.solid_fraction_local();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) sol[k][j][i] += solid_.a[(static_cast<std::size_t>(k) * ny + j) * nx + i];
  if (forces) {
    for (int c = 0; c < 3; ++c) {
      PetscScalar*** Ka = fs.drag_coefficient_local(c);
      PetscScalar*** KUa = fs.drag_momentum_local(c);
      PetscScalar*** Sa = fs.source_local(c);
      for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            const std::size_t q = (static_cast<std::size_t>(k) * K_[c].ny + j) * nx + i;  // v has ny + 1 rows
            Ka[k][j][i] += K_[c].a[q];
            KUa[k][j][i] += KU_[c].a[q];
            Sa[k][j][i] += S_[c].a[q];
          }
    }
  }
  fs.end_deposition();
  double amin = 1.0, amax = 0.0;
  for (double v : solid_.a) {
    amin = std::min(amin, 1.0 - v);
    amax = std::max(amax, 1.0 - v);
  }
  totals_.min_alpha_f = amin;
  totals_.max_alpha_f = amax;
  seconds_deposit += since(t0);
}

}  // namespace boycott::coupling
