// Coupler::deposit: particle volume into alpha_f, and the drag (K, K u_p) and the explicit
// reactions of a sub-cycle onto the fluid's faces, with one set of kernel weights per particle,
// summed over the ranks that share a plane and armed in the fluid for its next step.
#include <algorithm>
#include <chrono>
#include <vector>

#include "core/constants.hpp"
#include "core/timers.hpp"
#include "coupling/coupler.hpp"
#include "coupling/stencil_sums.hpp"
#include "fluid/fluid_solver.hpp"
#include "particles/dem_system.hpp"

namespace boycott::coupling {

void Coupler::deposit(particles::DemSystem& dem, fluid::FluidSolver& fs, double dt_s) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool forces = dt_s > 0.0;
  std::fill(solid_.a.begin(), solid_.a.end(), 0.0);
  for (int c = 0; c < 3; ++c) std::fill(drag_[c].begin(), drag_[c].end(), 0.0);
  // the lag and the mismatch are prepare's
  const auto lag = totals_.lag_impulse_ns, mismatch = totals_.sampling_mismatch_ns;
  totals_ = ExchangeTotals{};
  totals_.lag_impulse_ns = lag;
  totals_.sampling_mismatch_ns = mismatch;
  std::vector<double> reaction = deposit_particles(dem, dt_s);
  // The planes this rank owns: on one rank the whole grid as deposited; on several, every
  // rank's deposits there added up (and copied back into the window, whose other planes then
  // hold their owners' totals for the next prepare's alpha_f).
  std::vector<double> own_solid;
  if (window_) {
    own_solid = sum_owned(solid_);
    window_->fill(own_solid.data(), solid_.a.data(), solid_.plane_size());
  }
  const std::vector<double>& solid = window_ ? own_solid : solid_.a;
  const double vcell = g_.cell_volume_m3();
  double volume = 0.0;
  for (double v : solid) volume += v * vcell;
  totals_.solid_volume_m3 = window_ ? particles::ordered_sum(window_->comm(), volume) : volume;
  if (window_) reaction = particles::ordered_sum(window_->comm(), reaction);
  for (int c = 0; c < 3; ++c) totals_.reaction_n[c] = reaction[c];
  fs.begin_deposition();
  add_solid_fraction(fs, solid);
  if (forces)
    for (int c = 0; c < 3; ++c) add_drag_and_sources(fs, c);
  fs.end_deposition();
  record_alpha_range(solid);
  seconds_deposit += seconds_since(t0);
}

[[gnu::always_inline]] inline void Coupler::deposit_drag(const Stencil& st, const particles::ParticleStore& p,
                                                         std::size_t i, const double (&rf)[3], double dt_s) {
  // The fluid's drag is K (u_p - u) with K u_p = beta u_f(n) - J / dt: with u at level n it
  // returns exactly the impulse J the kicks applied.
  const double vcell = g_.cell_volume_m3();
  const double J[3] = {p.drag_jx[i], p.drag_jy[i], p.drag_jz[i]};
  const double uf[3] = {p.ufx[i], p.ufy[i], p.ufz[i]};
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

std::vector<double> Coupler::deposit_particles(particles::DemSystem& dem, double dt_s) {
  auto& p = dem.particles();
  const double vcell = g_.cell_volume_m3();
  const auto& lo = dem.config().box.lo;
  const bool forces = dt_s > 0.0;
  std::vector<double> reaction(3, 0.0);
  for (std::size_t i = 0; i < p.n_local; ++i) {
    const Stencil st = stencil(p.x[i] - lo[0], p.y[i] - lo[1], p.z[i] - lo[2]);
    const double r = p.radius[i];
    const double frac = (4.0 / 3.0) * kPi * r * r * r / vcell;
    scatter(offsets(st.cell[0], st.cell[1], st.cell[2], solid_),
            [&](std::size_t q, double w) { solid_.a[q] += w * frac; });
    if (!forces) continue;
    // The reaction to the explicit forces uses the particle's actual velocity change (added
    // mass).
    const double vs[3] = {p.vx[i], p.vy[i], p.vz[i]};
    const double v0[3] = {p.v0x[i], p.v0y[i], p.v0z[i]};
    const double react[3] = {p.react_x[i], p.react_y[i], p.react_z[i]};
    double rf[3];
    for (int c = 0; c < 3; ++c) {
      rf[c] = react[c];
      if (s_.added_mass)
        rf[c] += 0.5 * s_.rho_f_kg_m3 * (4.0 / 3.0) * kPi * r * r * r * (vs[c] - v0[c]) / dt_s;
      reaction[c] += rf[c];
    }
    deposit_drag(st, p, i, rf, dt_s);
  }
  return reaction;
}

void Coupler::add_solid_fraction(fluid::FluidSolver& fs, const std::vector<double>& solid) const {
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const int k_lo = window_ ? window_->own_begin() : 0, k_hi = window_ ? window_->own_end() : (int)g_.n[2];
  PetscScalar*** sol = fs.solid_fraction_local();
  for (int k = k_lo; k < k_hi; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        sol[k][j][i] += solid[(static_cast<std::size_t>(k - k_lo) * ny + j) * nx + i];
}

void Coupler::add_drag_and_sources(fluid::FluidSolver& fs, int c) const {
  // The y-wall rows of v are not fluid unknowns: the share deposited there goes into the wall.
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const int k_lo = window_ ? window_->own_begin() : 0, k_hi = window_ ? window_->own_end() : (int)g_.n[2];
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

void Coupler::record_alpha_range(const std::vector<double>& solid) {
  double amin = 1.0, amax = 0.0;
  for (double v : solid) {
    amin = std::min(amin, 1.0 - v);
    amax = std::max(amax, 1.0 - v);
  }
  totals_.min_alpha_f = window_ ? particles::global_min(window_->comm(), amin) : amin;
  totals_.max_alpha_f = window_ ? particles::global_max(window_->comm(), amax) : amax;
}

}  // namespace boycott::coupling
