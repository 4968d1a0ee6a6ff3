#include "coupling/coupler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/constants.hpp"
#include "core/error.hpp"
#include "core/timers.hpp"
#include "coupling/drag_laws.hpp"
#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::coupling {

CouplingSettings CouplingSettings::from_case(const CaseParams& p) {
  CouplingSettings s;
  s.drag = p.forces.drag;
  s.lift = p.forces.saffman_lift ? lift_law_from_name(p.forces.lift) : LiftLaw::none;
  s.added_mass = p.forces.added_mass;
  s.pressure_gradient = p.forces.pressure_gradient;
  s.viscous = p.forces.viscous;
  s.kernel = kernel_from_name(p.numerics.void_fraction_kernel);
  s.sampling = sampling_from_name(p.numerics.sampling);
  s.edge_vorticity = edge_vorticity_from_name(p.numerics.vorticity);
  s.rho_f_kg_m3 = p.fluid.density_kg_m3;
  s.mu_pa_s = p.fluid.viscosity_pa_s;
  s.top_slip = p.domain.top_wall == "slip";
  return s;
}

Coupler::Coupler(const CouplingSettings& s, const GridSpec& g, std::shared_ptr<const SlabExchange> window)
    : s_(s), g_(g), window_(std::move(window)), fields_(g, s.top_slip, window_.get(), s.edge_vorticity) {
  bool per[3] = {g.periodic[0], g.periodic[1], g.periodic[2]};
  const int nx = (int)g.n[0], ny = (int)g.n[1];
  int nz = (int)g.n[2], k0 = 0;
  if (window_) nz = window_->window_planes(), k0 = window_->window_begin(), per[2] = false;
  solid_.resize(nx, ny, nz, per, k0);
  for (int c = 0; c < 3; ++c) {
    const int nyc = (c == 1 && !g.periodic[1]) ? ny + 1 : ny;
    face_layout_[c].resize(nx, nyc, nz, per, k0);
    drag_[c].assign(3 * face_layout_[c].a.size(), 0.0);
    face_layout_[c].a = {};
  }
}

Coupler::Stencil Coupler::stencil(double x, double y, double z) const {
  Stencil st;
  const double pos[3] = {x, y, z};
  for (int d = 0; d < 3; ++d) {
    st.cell[d] = cell_weights(s_.kernel, pos[d], g_.dx(d), (int)g_.n[d], !g_.periodic[d]);
    if (d == 2 && window_) {
      // The particle's periodic image that lies in this rank's window.
      const int nz = (int)g_.n[2], lo = solid_.k0, hi = solid_.k0 + solid_.nz;
      Weights1D& w = st.cell[2];
      const int first = w.first;
      while (w.first < lo) w.first += nz;
      while (w.first + w.n + 1 > hi) w.first -= nz;
      st.z_image = w.first - first;
      if (w.first < lo)
        throw PhysicsError(fmt::format(
            "a particle at z = {:.6g} m is outside the planes its rank holds ({} to {})", z, lo, hi - 1));
    }
    st.face[d] = face_weights(st.cell[d]);
  }
  return st;
}

Coupler::LinearStencil Coupler::linear_stencil(double x, double y, double z, int z_image) const {
  LinearStencil st;
  const double hx = g_.dx(0), hy = g_.dx(1), hz = g_.dx(2);
  const int nx = (int)g_.n[0], ny = (int)g_.n[1], nz = (int)g_.n[2];
  const bool walls = !g_.periodic[1];
  for (int f = 0; f < 2; ++f) {
    const bool centred = f == 0;
    st.x[f] = linear_weights(x, hx, centred, nx, false, WallRule::plain, WallRule::plain);
    st.z[f] = linear_weights(z, hz, centred, nz, false, WallRule::plain, WallRule::plain);
    if (window_) {
      // The same periodic image as the kernel's (stencil()); the linear stencil reaches no
      // further than the kernel's, whose planes the window holds.
      Weights1D& w = st.z[f];
      w.first += z_image;
      const int lo = solid_.k0 + 1, hi = solid_.k0 + solid_.nz - 2;
      if (w.first < lo || w.first + w.n > hi)
        throw PhysicsError(fmt::format(
            "a particle at z = {:.6g} m is outside the planes its rank holds ({} to {})", z, lo, hi - 1));
    }
  }
  const WallRule top = s_.top_slip ? WallRule::constant : WallRule::zero;
  const WallRule ex = WallRule::extrapolate;
  st.y_tangential = linear_weights(y, hy, true, ny, walls, WallRule::zero, top);
  st.y_normal = linear_weights(y, hy, false, ny, walls, WallRule::plain, WallRule::plain);
  st.y_centre_extrapolated = linear_weights(y, hy, true, ny, walls, ex, ex);
  st.y_face_extrapolated = linear_weights(y, hy, false, ny, walls, ex, ex);
  st.y_alpha = linear_weights(y, hy, true, ny, walls, WallRule::constant, WallRule::constant);
  return st;
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
    // A window of planes (several ranks) is indexed from its first plane.
    const int first = W[d]->first - (d == 2 ? f.k0 : 0);
    for (int a = 0; a < W[d]->n; ++a) {
      const int i = f.periodic[d] ? GridField::wrap(first + a, dim[d]) : first + a;
      o.off[d][a] = static_cast<std::size_t>(i) * stride[d];
      o.w[d][a] = W[d]->w[a];
    }
  }
  return o;
}

/// For each of N fields that share one layout, the sum over the stencil of
/// w_x(i) w_y(j) w_z(k) f(i,j,k) (x inside y inside z), in one pass: the offsets and weights are
/// read once for all of them, and each field's sums run in the same order as alone.
template <int N>
inline void sample_fields(const Offsets3& o, const double* const (&f)[N], double (&out)[N]) {
  double s[N] = {};
  for (int c = 0; c < o.n[2]; ++c) {
    double sy[N] = {};
    for (int b = 0; b < o.n[1]; ++b) {
      const std::size_t row = o.off[2][c] + o.off[1][b];
      double sx[N] = {};
      for (int a = 0; a < o.n[0]; ++a) {
        const std::size_t q = row + o.off[0][a];
        for (int m = 0; m < N; ++m) sx[m] += o.w[0][a] * f[m][q];
      }
      for (int m = 0; m < N; ++m) sy[m] += o.w[1][b] * sx[m];
    }
    for (int m = 0; m < N; ++m) s[m] += o.w[2][c] * sy[m];
  }
  for (int m = 0; m < N; ++m) out[m] = s[m];
}

/// Sum over the stencil of w_x(i) w_y(j) w_z(k) f(i,j,k).
inline double sample(const Offsets3& o, const std::vector<double>& field) {
  const double* const f[1] = {field.data()};
  double v[1];
  sample_fields(o, f, v);
  return v[0];
}

/// Calls f(index, w_x w_y w_z) for every stencil point.
template <class F>
inline void scatter(const Offsets3& o, F&& f) {
  for (int c = 0; c < o.n[2]; ++c)
    for (int b = 0; b < o.n[1]; ++b)
      for (int a = 0; a < o.n[0]; ++a)
        f(o.off[2][c] + o.off[1][b] + o.off[0][a], o.w[0][a] * o.w[1][b] * o.w[2][c]);
}

}  // namespace

template <class Law>
void Coupler::prepare_impl(const Law& law, particles::DemSystem& dem, double dt_prev) {
  auto& p = dem.particles();
  const double rho = s_.rho_f_kg_m3, mu = s_.mu_pa_s, nu = mu / rho;
  const auto& lo = dem.config().box.lo;
  const bool linear = s_.sampling == Sampling::trilinear;
  std::vector<double> lag(3, 0.0);       // this rank's share of totals_.lag_impulse_ns
  std::vector<double> mismatch(3, 0.0);  // and of totals_.sampling_mismatch_ns
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const double px = p.x[i] - lo[0], py = p.y[i] - lo[1], pz = p.z[i] - lo[2];
    const Stencil st = stencil(px, py, pz);
    const double d = 2.0 * p.radius[i];
    const double vp = kPi * d * d * d / 6.0;
    double uf[3], fe[3] = {0.0, 0.0, 0.0}, dudt[3] = {0.0, 0.0, 0.0};
    double ufk[3], fek[3] = {0.0, 0.0, 0.0};  // read with the kernel's weights (trilinear: mismatch)
    LinearStencil ls;
    if (linear) ls = linear_stencil(px, py, pz, st.z_image);
    double pg_y = 0.0, visc_y = 0.0;  // the force budget's split of fe[1]
    for (int c = 0; c < 3; ++c) {
      const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
      const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
      const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
      // the face fields of component c share one layout
      const Offsets3 o = offsets(wx, wy, wz, fields_.velocity(c));
      if (!linear) {
        // the four face fields in one pass (a field whose force is off is read and not used)
        const double* const f[4] = {fields_.velocity(c).a.data(), fields_.pressure_gradient(c).a.data(),
                                    fields_.viscous(c).a.data(), fields_.material_derivative(c).a.data()};
        double v[4];
        sample_fields(o, f, v);
        uf[c] = v[0];
        if (s_.pressure_gradient) fe[c] -= vp * v[1];
        if (s_.viscous) fe[c] += rho * vp * v[2];
        if (s_.added_mass) dudt[c] = v[3];
        if (c == 1 && budget_) {
          pg_y = s_.pressure_gradient ? -vp * v[1] : 0.0;
          visc_y = s_.viscous ? rho * vp * v[2] : 0.0;
        }
        continue;
      }
      const Weights1D& lx = ls.x[c == 0 ? 1 : 0];
      const Weights1D& lz = ls.z[c == 2 ? 1 : 0];
      const Offsets3 ou = offsets(lx, c == 1 ? ls.y_normal : ls.y_tangential, lz, fields_.velocity(c));
      const Offsets3 og =
          offsets(lx, c == 1 ? ls.y_face_extrapolated : ls.y_centre_extrapolated, lz, fields_.velocity(c));
      uf[c] = sample(ou, fields_.velocity(c).a);
      ufk[c] = sample(o, fields_.velocity(c).a);
      if (s_.pressure_gradient) {
        fe[c] -= vp * sample(og, fields_.pressure_gradient(c).a);
        fek[c] -= vp * sample(o, fields_.pressure_gradient(c).a);
        if (c == 1) pg_y = fe[c];
      }
      if (s_.viscous) {
        const double fv = rho * vp * sample(og, fields_.viscous(c).a);
        fe[c] += fv;
        fek[c] += rho * vp * sample(o, fields_.viscous(c).a);
        if (c == 1) visc_y = fv;
      }
      if (s_.added_mass) dudt[c] = sample(og, fields_.material_derivative(c).a);
    }
    if (linear)
      for (int c = 0; c < 3; ++c) mismatch[c] += dt_prev * (p.beta[i] * (ufk[c] - uf[c]) + (fek[c] - fe[c]));
    // Time-level lag (see coupler.hpp): what the fluid gave at level n+1 minus what the particle
    // received at level n over the last sub-cycle, both with these weights. Measured, not fed
    // back: handing it to the fluid as an explicit source undoes the implicit drag (a frozen
    // dense bed diverges) and feeds pressure jumps back in dense beds.
    {
      const double ufo[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
      double* fpv[3] = {&p.fpv_x[i], &p.fpv_y[i], &p.fpv_z[i]};
      for (int c = 0; c < 3; ++c) {
        lag[c] += dt_prev * (p.beta[i] * (uf[c] - ufo[c]) + (fe[c] - *fpv[c]));
        *fpv[c] = fe[c];
      }
      p.drag_jx[i] = p.drag_jy[i] = p.drag_jz[i] = 0.0;
    }
    const Offsets3 oc = linear ? offsets(ls.x[0], ls.y_centre_extrapolated, ls.z[0], solid_)
                               : offsets(st.cell[0], st.cell[1], st.cell[2], solid_);  // cell-centred fields
    // the vorticity (cell-centred, like the solid fraction) in the solid fraction's pass
    double w[3] = {0.0, 0.0, 0.0};
    double solid;
    if (s_.edge_vorticity) {
      // Each component from its own edges (fluid_fields.hpp), with the weights of its location.
      solid = linear ? sample(offsets(ls.x[0], ls.y_alpha, ls.z[0], solid_), solid_.a) : sample(oc, solid_.a);
      if (s_.lift != LiftLaw::none) {
        if (linear) {
          w[0] = sample(offsets(ls.x[0], ls.y_normal, ls.z[1], fields_.vorticity(0)), fields_.vorticity(0).a);
          w[1] = sample(offsets(ls.x[1], ls.y_tangential, ls.z[1], fields_.vorticity(1)),
                        fields_.vorticity(1).a);
          w[2] = sample(offsets(ls.x[1], ls.y_normal, ls.z[0], fields_.vorticity(2)), fields_.vorticity(2).a);
        } else {
          w[0] = sample(offsets(st.cell[0], st.face[1], st.face[2], fields_.vorticity(0)),
                        fields_.vorticity(0).a);
          w[1] = sample(offsets(st.face[0], st.cell[1], st.face[2], fields_.vorticity(1)),
                        fields_.vorticity(1).a);
          w[2] = sample(offsets(st.face[0], st.face[1], st.cell[2], fields_.vorticity(2)),
                        fields_.vorticity(2).a);
        }
      }
    } else if (!linear) {  // the vorticity is read whether or not the lift uses it
      const double* const f[4] = {solid_.a.data(), fields_.vorticity(0).a.data(),
                                  fields_.vorticity(1).a.data(), fields_.vorticity(2).a.data()};
      double v[4];
      sample_fields(oc, f, v);
      solid = v[0], w[0] = v[1], w[1] = v[2], w[2] = v[3];
    } else {
      solid = sample(offsets(ls.x[0], ls.y_alpha, ls.z[0], solid_), solid_.a);
      if (s_.lift != LiftLaw::none)
        for (int c = 0; c < 3; ++c) w[c] = sample(oc, fields_.vorticity(c).a);
    }
    const double alpha_f = 1.0 - solid;
    const double s0 = uf[0] - p.vx[i], s1 = uf[1] - p.vy[i], s2 = uf[2] - p.vz[i];
    const double slip = std::sqrt(s0 * s0 + s1 * s1 + s2 * s2);
    p.beta[i] = law.beta(alpha_f, slip, d, rho, mu);
    p.ufx[i] = uf[0], p.ufy[i] = uf[1], p.ufz[i] = uf[2];

    double react[3] = {0.0, 0.0, 0.0};
    double fl[3] = {0.0, 0.0, 0.0};
    if (s_.lift != LiftLaw::none) {
      lift_force(s_.lift, {s0, s1, s2}, w, d, rho, nu, fl);
      for (int c = 0; c < 3; ++c) fe[c] += fl[c], react[c] -= fl[c];
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
    if (budget_) {
      budget_->add_prepared(ForceBudget::lift, p.y[i], fl[1]);
      budget_->add_prepared(ForceBudget::pressure_gradient, p.y[i], pg_y);
      budget_->add_prepared(ForceBudget::viscous, p.y[i], visc_y);
      budget_->add_prepared(ForceBudget::added_mass, p.y[i], p.madd[i] * dudt[1]);
      budget_->add_prepared(ForceBudget::re_p, p.y[i], slip * d / nu);
      budget_->add_prepared(ForceBudget::re_w, p.y[i],
                            std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * d * d / nu);
    }

    p.v0x[i] = p.vx[i], p.v0y[i] = p.vy[i], p.v0z[i] = p.vz[i];
    p.react_x[i] = react[0], p.react_y[i] = react[1], p.react_z[i] = react[2];
  }
  if (window_) lag = particles::ordered_sum(window_->comm(), lag);
  for (int c = 0; c < 3; ++c) totals_.lag_impulse_ns[c] = lag[c];
  if (linear && window_) mismatch = particles::ordered_sum(window_->comm(), mismatch);
  for (int c = 0; c < 3; ++c) totals_.sampling_mismatch_ns[c] = mismatch[c];
}

std::vector<double> Coupler::gather_whole(const GridField& f) const {
  if (!window_) return f.a;
  const std::size_t ps = f.plane_size();
  const auto first = f.a.begin() + static_cast<std::ptrdiff_t>((window_->own_begin() - f.k0) * ps);
  const std::vector<double> own(
      first, first + static_cast<std::ptrdiff_t>((window_->own_end() - window_->own_begin()) * ps));
  return gather_planes(own);
}

std::vector<double> Coupler::gather_planes(const std::vector<double>& own) const {
  // Rank order is plane order: the slabs are consecutive.
  const MPI_Comm comm = window_->comm();
  const int ranks = window_->ranks();
  const int n = static_cast<int>(own.size());
  std::vector<int> counts(ranks), displs(ranks);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  int total = 0;
  for (int r = 0; r < ranks; ++r) displs[r] = total, total += counts[r];
  std::vector<double> all(window_->rank() == 0 ? static_cast<std::size_t>(total) : 0);
  MPI_Gatherv(own.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0, comm);
  return all;
}

std::vector<std::vector<double>> Coupler::export_state() const {
  auto st = fields_.export_state();
  if (window_)
    for (int c = 0; c < 3; ++c) st[c] = gather_planes(st[c]);
  st.push_back(gather_whole(solid_));
  return st;
}

void Coupler::import_state(const std::vector<std::vector<double>>& st, particles::DemSystem& dem) {
  // 5 arrays: u, v, w, the previous-level flag, the solid fraction. Earlier versions kept the
  // pressure-gradient and viscous force of the last prepare per particle id (arrays 4-6).
  if (st.size() != 5 && st.size() != 8) throw CheckpointError("coupling state: expected 5 (or 8) arrays");
  const auto& solid = st.back();
  const std::size_t ps = solid_.plane_size(), nz = g_.n[2];
  if (solid.size() != ps * nz) throw CheckpointError("coupling state: solid fraction of another grid");
  for (int p = 0; p < solid_.nz; ++p) {
    const std::size_t k = static_cast<std::size_t>(((solid_.k0 + p) % (int)nz + (int)nz) % (int)nz);
    std::copy(solid.begin() + static_cast<std::ptrdiff_t>(k * ps),
              solid.begin() + static_cast<std::ptrdiff_t>((k + 1) * ps),
              solid_.a.begin() + static_cast<std::ptrdiff_t>(p * ps));
  }
  fields_.import_state({st.begin(), st.begin() + 4});
  if (st.size() == 8) {
    auto& p = dem.particles();
    for (std::size_t i = 0; i < p.n_local; ++i) {
      const auto k = static_cast<std::size_t>(p.id[i]);
      if (p.id[i] < 0 || k >= st[4].size())
        throw CheckpointError(fmt::format("coupling state: no force of particle {}", p.id[i]));
      p.fpv_x[i] = st[4][k], p.fpv_y[i] = st[5][k], p.fpv_z[i] = st[6][k];
    }
  }
}

std::vector<double> Coupler::sum_owned(const GridField& f) const {
  std::vector<double> owned(f.plane_size() *
                            static_cast<std::size_t>(window_->own_end() - window_->own_begin()));
  window_->sum_to_owned(f.a.data(), owned.data(), f.plane_size());
  return owned;
}

void Coupler::prepare(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_prev_s) {
  const auto t0 = std::chrono::steady_clock::now();
  fields_.update(fs, dt_prev_s, s_.viscous, s_.added_mass, s_.lift != LiftLaw::none);
  totals_.lag_impulse_ns = {0.0, 0.0, 0.0};
  totals_.sampling_mismatch_ns = {0.0, 0.0, 0.0};
  visit_drag_law(s_.drag, [&](const auto& law) { prepare_impl(law, dem, dt_prev_s); });
  seconds_sample += seconds_since(t0);
}

void Coupler::deposit(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_s) {
  const auto t0 = std::chrono::steady_clock::now();
  auto& p = dem.particles();
  const double vcell = g_.cell_volume_m3();
  const auto& lo = dem.config().box.lo;
  std::fill(solid_.a.begin(), solid_.a.end(), 0.0);
  for (int c = 0; c < 3; ++c) std::fill(drag_[c].begin(), drag_[c].end(), 0.0);
  const bool forces = dt_s > 0.0;
  const auto lag = totals_.lag_impulse_ns, mismatch = totals_.sampling_mismatch_ns;
  totals_ = ExchangeTotals{};
  totals_.lag_impulse_ns = lag;
  totals_.sampling_mismatch_ns = mismatch;
  std::vector<double> reaction(3, 0.0);
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const Stencil st = stencil(p.x[i] - lo[0], p.y[i] - lo[1], p.z[i] - lo[2]);
    const double r = p.radius[i];
    const double frac = (4.0 / 3.0) * kPi * r * r * r / vcell;
    scatter(offsets(st.cell[0], st.cell[1], st.cell[2], solid_),
            [&](std::size_t q, double w) { solid_.a[q] += w * frac; });
    if (!forces) continue;
    // The fluid's drag is K (u_p - u) with K u_p = beta u_f(n) - J / dt: with u at level n it
    // returns exactly the impulse J the kicks applied. The reaction to the explicit forces uses
    // the particle's actual velocity change (added mass).
    const double vs[3] = {p.vx[i], p.vy[i], p.vz[i]};
    const double v0[3] = {p.v0x[i], p.v0y[i], p.v0z[i]};
    const double react[3] = {p.react_x[i], p.react_y[i], p.react_z[i]};
    const double J[3] = {p.drag_jx[i], p.drag_jy[i], p.drag_jz[i]};
    const double uf[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
    double rf[3];
    for (int c = 0; c < 3; ++c) {
      rf[c] = react[c];
      if (s_.added_mass)
        rf[c] += 0.5 * s_.rho_f_kg_m3 * (4.0 / 3.0) * kPi * r * r * r * (vs[c] - v0[c]) / dt_s;
      reaction[c] += rf[c];
    }
    const double b = p.beta[i];
    for (int c = 0; c < 3; ++c) {
      const Weights1D& wx = c == 0 ? st.face[0] : st.cell[0];
      const Weights1D& wy = c == 1 ? st.face[1] : st.cell[1];
      const Weights1D& wz = c == 2 ? st.face[2] : st.cell[2];
      const double kb = b / vcell, kub = (b * uf[c] - J[c] / dt_s) / vcell, sr = rf[c] / vcell;
      double* dc = drag_[c].data();
      scatter(offsets(wx, wy, wz, face_layout_[c]), [&](std::size_t q, double w) {
        double* v = dc + 3 * q;
        v[0] += w * kb;
        v[1] += w * kub;
        v[2] += w * sr;
      });
    }
  }
  // The planes this rank owns: on one rank the whole grid as deposited; on several, every
  // rank's deposits there added up (and copied back into the window, whose other planes then
  // hold their owners' totals for the next prepare's alpha_f).
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const int k_lo = window_ ? window_->own_begin() : 0, k_hi = window_ ? window_->own_end() : (int)g_.n[2];
  std::vector<double> own_solid;
  if (window_) {
    own_solid = sum_owned(solid_);
    window_->fill(own_solid.data(), solid_.a.data(), solid_.plane_size());
  }
  const std::vector<double>& solid = window_ ? own_solid : solid_.a;
  double volume = 0.0;
  for (double v : solid) volume += v * vcell;
  totals_.solid_volume_m3 = window_ ? particles::ordered_sum(window_->comm(), volume) : volume;
  if (window_) reaction = particles::ordered_sum(window_->comm(), reaction);
  for (int c = 0; c < 3; ++c) totals_.reaction_n[c] = reaction[c];

  // Into the fluid's deposition arrays. The y-wall rows of v are not fluid unknowns: the share
  // deposited there goes into the wall.
  fs.begin_deposition();
  PetscScalar*** sol = fs.solid_fraction_local();
  for (int k = k_lo; k < k_hi; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        sol[k][j][i] += solid[(static_cast<std::size_t>(k - k_lo) * ny + j) * nx + i];
  if (forces) {
    for (int c = 0; c < 3; ++c) {
      PetscScalar*** Ka = fs.drag_coefficient_local(c);
      PetscScalar*** KUa = fs.drag_momentum_local(c);
      PetscScalar*** Sa = fs.source_local(c);
      const GridField& f = face_layout_[c];
      std::vector<double> own;
      if (window_) {
        // a plane of the interleaved array is 3 plane_size() values
        own.resize(3 * f.plane_size() * static_cast<std::size_t>(window_->own_end() - window_->own_begin()));
        window_->sum_to_owned(drag_[c].data(), own.data(), 3 * f.plane_size());
      }
      const double* v = window_ ? own.data() : drag_[c].data();
      for (int k = k_lo; k < k_hi; ++k)
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            const std::size_t q =
                3 * ((static_cast<std::size_t>(k - k_lo) * f.ny + j) * nx + i);  // v: ny + 1 rows
            Ka[k][j][i] += v[q];
            KUa[k][j][i] += v[q + 1];
            Sa[k][j][i] += v[q + 2];
          }
    }
  }
  fs.end_deposition();
  double amin = 1.0, amax = 0.0;
  for (double v : solid) {
    amin = std::min(amin, 1.0 - v);
    amax = std::max(amax, 1.0 - v);
  }
  totals_.min_alpha_f = window_ ? particles::global_min(window_->comm(), amin) : amin;
  totals_.max_alpha_f = window_ ? particles::global_max(window_->comm(), amax) : amax;
  seconds_deposit += seconds_since(t0);
}

}  // namespace boycott::coupling
