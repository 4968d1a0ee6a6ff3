// The coupler's settings from a case, its grids, each particle's stencils (kernel and trilinear
// weights, the periodic image in this rank's window) and its checkpoint state. The sampling is in
// coupler_sample.cpp, the deposition in coupler_deposit.cpp.
#include "coupling/coupler.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
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
  s.drag_dt_limit = p.numerics.drag_dt_limit;
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

}  // namespace boycott::coupling
