// FluidFields' reading of the solver's level, the padded copies and the face fields derived from
// them (pressure gradient, viscous stress divergence, Du/Dt); the vorticity is in
// fluid_fields_vorticity.cpp.
#include "coupling/fluid_fields.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "coupling/slab_exchange.hpp"
#include "fluid/fluid_solver.hpp"
#include "fluid/staggering.hpp"

namespace boycott::coupling {

using fluid::kE;

FluidFields::FluidFields(const GridSpec& g, bool top_slip, const SlabExchange* window, bool edge_vorticity)
    : g_(g), walls_(!g.periodic[1]), top_slip_(top_slip), edge_vorticity_(edge_vorticity), window_(window) {
  bool per[3] = {g.periodic[0], g.periodic[1], g.periodic[2]};
  const int nx = (int)g.n[0], ny = (int)g.n[1];
  int nz = (int)g.n[2], k0 = 0;
  kb_ = 0, ke_ = nz, kce_ = nz, kofs_ = 0;
  if (window_) {
    // The window reaches kWindowBelow planes below the slab and kWindowAbove above: the fields
    // are derived one plane inside it (their stencils reach one plane), the vorticity two
    // below its top (its cell-centred velocity reaches two faces up).
    nz = window_->window_planes(), k0 = window_->window_begin(), per[2] = false;
    kb_ = k0 + 1, ke_ = k0 + nz - 1, kce_ = k0 + nz - 2, kofs_ = k0;
  }
  for (int c = 0; c < 3; ++c) {
    const int nyc = (c == 1 && walls_) ? ny + 1 : ny;
    for (GridField* f : {&u_[c], &uprev_[c], &gradp_[c], &visc_[c], &dudt_[c]})
      f->resize(nx, nyc, nz, per, k0);
    // Edges: omega_x and omega_z have the y faces (walls included).
    vort_[c].resize(nx, edge_vorticity_ && c != 1 && walls_ ? ny + 1 : ny, nz, per, k0);
  }
  p_.resize(nx, ny, nz, per, k0);
  nut_.resize(nx, ny, nz, per, k0);
}

std::vector<std::vector<double>> FluidFields::export_state() const {
  std::vector<std::vector<double>> st;
  for (int c = 0; c < 3; ++c) {
    if (!window_) {
      st.push_back(u_[c].a);
      continue;
    }
    const std::size_t ps = u_[c].plane_size();
    const auto first = u_[c].a.begin() + static_cast<std::ptrdiff_t>((window_->own_begin() - u_[c].k0) * ps);
    st.emplace_back(first,
                    first + static_cast<std::ptrdiff_t>((window_->own_end() - window_->own_begin()) * ps));
  }
  st.push_back({have_prev_ ? 1.0 : 0.0});
  return st;
}

void FluidFields::import_state(const std::vector<std::vector<double>>& st) {
  if (st.size() != 4 || st[3].size() != 1)
    throw CheckpointError("coupling state: expected 3 velocity arrays and a flag");
  const int nz = (int)g_.n[2];
  for (int c = 0; c < 3; ++c) {
    const std::size_t ps = u_[c].plane_size(), whole = ps * static_cast<std::size_t>(nz);
    if (st[c].size() != whole)
      throw CheckpointError(
          fmt::format("coupling state: velocity {} has {} values, the grid {}", c, st[c].size(), whole));
    if (!window_) {
      u_[c].a = st[c];
      continue;
    }
    for (int p = 0; p < u_[c].nz; ++p) {
      const int k = ((u_[c].k0 + p) % nz + nz) % nz;
      std::copy(st[c].begin() + static_cast<std::ptrdiff_t>(k * ps),
                st[c].begin() + static_cast<std::ptrdiff_t>((k + 1) * ps),
                u_[c].a.begin() + static_cast<std::ptrdiff_t>(p * ps));
    }
  }
  have_prev_ = st[3][0] != 0.0;
}

double FluidFields::nu_cell(int i, int j, int k) const {
  return nu_ + nut_.at(i, j, k);
}

template <class Rule>
void FluidFields::fill_padded(Padded& dst, int nx, int ny, int nz, Rule&& value) {
  constexpr int p = Padded::kPad;
  dst.nx = nx + 2 * p, dst.ny = ny + 2 * p;
  dst.a.resize(static_cast<std::size_t>(nx + 2 * p) * (ny + 2 * p) * (nz + 2 * p));
  std::size_t q = 0;
  for (int k = -p; k < nz + p; ++k)
    for (int j = -p; j < ny + p; ++j)
      for (int i = -p; i < nx + p; ++i) dst.a[q++] = value(i, j, k);
}

void FluidFields::update(fluid::FluidSolver& fs, double dt_s, bool need_viscous, bool need_material,
                         bool need_vorticity) {
  rho_ = fs.settings().density_kg_m3;
  nu_ = fs.settings().viscosity_pa_s / rho_;
  for (int c = 0; c < 3; ++c) std::swap(u_[c].a, uprev_[c].a);
  read_solver_fields(fs);
  fill_padded_copies();
  const bool first = !have_prev_ || dt_s <= 0.0;
  have_prev_ = true;
  const double G = fs.mean_pressure_gradient_pa_m();
  for (int c = 0; c < 3; ++c) update_face_fields(c, G, dt_s, first, need_viscous, need_material);
  // Wall rows are not fluid unknowns; a particle near the wall still feels the hydrostatic
  // gradient there, so they take the nearest interior face's value.
  if (walls_) copy_wall_rows_of_v();
  if (need_vorticity && edge_vorticity_) update_edge_vorticity();
  if (need_vorticity && !edge_vorticity_) update_centre_vorticity();
}

void FluidFields::read_solver_fields(fluid::FluidSolver& fs) {
  // Copy the solver's owned values (one rank: the whole grid); on several ranks the window's
  // other planes come from their owners.
  const int n[3] = {(int)g_.n[0], (int)g_.n[1], (int)g_.n[2]};
  const int k_lo = window_ ? window_->own_begin() : 0, k_hi = window_ ? window_->own_end() : n[2];
  const std::size_t plane = static_cast<std::size_t>(n[0]) * n[1];
  std::vector<double> owned, win;
  for (int c = 0; c < 5; ++c) {
    const PetscScalar* const* const* a = fs.read_local(c);
    GridField& dst = c < 3 ? u_[c] : (c == 3 ? p_ : nut_);
    if (!window_) {
      for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) dst.at(i, j, k) = a[k][j][i];
    } else {
      owned.resize(plane * static_cast<std::size_t>(k_hi - k_lo));
      std::size_t q = 0;
      for (int k = k_lo; k < k_hi; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) owned[q++] = a[k][j][i];
      win.resize(plane * static_cast<std::size_t>(dst.nz));
      window_->fill(owned.data(), win.data(), plane);
      for (int p = 0; p < dst.nz; ++p)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
            dst.at(i, j, dst.k0 + p) = win[(static_cast<std::size_t>(p) * n[1] + j) * n[0] + i];
    }
    fs.restore_read(c);
  }
  if (walls_) {
    for (int k = u_[0].k0; k < u_[0].k0 + u_[0].nz; ++k)
      for (int i = 0; i < n[0]; ++i) u_[1].at(i, 0, k) = u_[1].at(i, n[1], k) = 0.0;
  }
}

void FluidFields::fill_padded_copies() {
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  // The planes the fields hold: the whole grid, or the window. Padded copies are indexed from
  // plane kofs_; in a window, the pad planes beyond it are never read.
  const int planes = u_[0].nz;
  auto in_window = [&](int k) { return !window_ || (k >= 0 && k < planes); };
  for (int c = 0; c < 3; ++c)
    fill_padded(upad_[c], nx, u_[c].ny, planes,
                [&](int i, int j, int k) { return in_window(k) ? uval(c, i, j, k + kofs_) : 0.0; });
  // p and nu_t are read inside the walls only (y rows 0 .. ny - 1); their y pads stay unread.
  // Wall mirror two rows out needs ny >= 2 (the fluid grid requires it).
  auto inside = [&](int j, int k) { return (!walls_ || (j >= 0 && j < ny)) && in_window(k); };
  fill_padded(ppad_, nx, ny, planes,
              [&](int i, int j, int k) { return inside(j, k) ? p_.at(i, j, k + kofs_) : 0.0; });
  fill_padded(nupad_, nx, ny, planes,
              [&](int i, int j, int k) { return inside(j, k) ? nu_cell(i, j, k + kofs_) : 0.0; });
}

/// One neighbour term of the viscous operator: the neighbour along d on side s.
struct FluidFields::ViscousTerm {
  enum class Kind { along, wall, across };
  Kind kind = Kind::along;
  int s = 1;
  bool slip = false;
  double h2 = 1.0, hd = 1.0;                                                // h_d^2, h_d
  const double *n0 = nullptr, *n1 = nullptr, *n2 = nullptr, *n3 = nullptr;  // nu reads
  const double *u0 = nullptr, *u1 = nullptr, *un = nullptr;                 // velocity reads
};

/// The reads of the material derivative's term along d.
struct FluidFields::ConvectionTerm {
  const double *a0, *a1, *a2, *a3, *b0, *b1;
};

void FluidFields::viscous_terms(int c, int j, int k, ViscousTerm (&terms)[6]) const {
  const int ec[3] = {kE[c][0], kE[c][1], kE[c][2]};
  const int jm = j - ec[1], km = k - ec[2];
  const Padded& Uc = upad_[c];
  for (int d = 0, t = 0; d < 3; ++d)
    for (int s = -1; s <= 1; s += 2, ++t) {
      ViscousTerm& T = terms[t];
      const double hd = g_.dx(d);
      T.s = s, T.h2 = hd * hd, T.hd = hd;
      const int N[3] = {s * kE[d][0], j + s * kE[d][1], k + s * kE[d][2]};  // i offset, j, k
      if (d == c) {
        T.kind = ViscousTerm::Kind::along;
        const int Q[3] = {s > 0 ? 0 : -ec[0], s > 0 ? j : jm, s > 0 ? k : km};
        T.n0 = padded_row(nupad_, Q[1], Q[2]) + Q[0];
        T.u0 = padded_row(Uc, Q[1], Q[2]) + Q[0];
        T.u1 = padded_row(Uc, Q[1] + ec[1], Q[2] + ec[2]) + Q[0] + ec[0];
        T.un = padded_row(Uc, N[1], N[2]) + N[0];
        continue;
      }
      const int E[3] = {s > 0 ? N[0] : 0, s > 0 ? N[1] : j, s > 0 ? N[2] : k};
      if (d == 1 && walls_ && (E[1] <= 0 || E[1] >= (int)g_.n[1])) {
        T.kind = ViscousTerm::Kind::wall;
        T.slip = s > 0 && top_slip_;
        T.n0 = padded_row(nupad_, j, k);
        T.n1 = padded_row(nupad_, jm, km) - ec[0];
        continue;
      }
      T.kind = ViscousTerm::Kind::across;
      const int O[3] = {E[0] - kE[d][0], E[1] - kE[d][1], E[2] - kE[d][2]};
      T.n0 = padded_row(nupad_, E[1], E[2]) + E[0];
      T.n1 = padded_row(nupad_, E[1] - ec[1], E[2] - ec[2]) + E[0] - ec[0];
      T.n2 = padded_row(nupad_, O[1], O[2]) + O[0];
      T.n3 = padded_row(nupad_, O[1] - ec[1], O[2] - ec[2]) + O[0] - ec[0];
      T.u1 = padded_row(upad_[d], E[1], E[2]) + E[0];
      T.u0 = padded_row(upad_[d], E[1] - ec[1], E[2] - ec[2]) + E[0] - ec[0];
      T.un = padded_row(Uc, N[1], N[2]) + N[0];
    }
}

void FluidFields::convection_terms(int c, int j, int k, ConvectionTerm (&cv)[3]) const {
  const int ec[3] = {kE[c][0], kE[c][1], kE[c][2]};
  const int jm = j - ec[1], km = k - ec[2];
  const Padded& Uc = upad_[c];
  for (int d = 0; d < 3; ++d) {
    const int e[3] = {kE[d][0], kE[d][1], kE[d][2]};
    const Padded& Ud = upad_[d];
    cv[d].a0 = padded_row(Ud, j, k);
    cv[d].a1 = padded_row(Ud, j + e[1], k + e[2]) + e[0];
    cv[d].a2 = padded_row(Ud, jm, km) - ec[0];
    cv[d].a3 = padded_row(Ud, jm + e[1], km + e[2]) - ec[0] + e[0];
    cv[d].b1 = padded_row(Uc, j + e[1], k + e[2]) + e[0];
    cv[d].b0 = padded_row(Uc, j - e[1], k - e[2]) - e[0];
  }
}

void FluidFields::update_face_fields(int c, double G, double dt_s, bool first, bool need_viscous,
                                     bool need_material) {
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const double h[3] = {g_.dx(0), g_.dx(1), g_.dx(2)};
  const int ec[3] = {kE[c][0], kE[c][1], kE[c][2]};
  const int nyc = u_[c].ny;
  const double addG = c == 2 ? G : 0.0;
  for (int k = kb_; k < ke_; ++k)
    for (int j = 0; j < nyc; ++j) {
      const bool wall_row = walls_ && c == 1 && (j == 0 || j == ny);
      if (wall_row) continue;  // filled from the nearest interior row (copy_wall_rows_of_v)
      const std::size_t o = (static_cast<std::size_t>(k - u_[c].k0) * nyc + j) * nx;  // (0, j, k), in range
      const double* up = u_[c].a.data() + o;
      const double* uq = uprev_[c].a.data() + o;
      double* gp = gradp_[c].a.data() + o;
      double* vs = visc_[c].a.data() + o;
      double* md = dudt_[c].a.data() + o;
      const double* p0 = padded_row(ppad_, j, k);
      const double* p1 = padded_row(ppad_, j - ec[1], k - ec[2]) - ec[0];
      ViscousTerm terms[6];
      if (need_viscous) viscous_terms(c, j, k, terms);
      ConvectionTerm cv[3];
      if (need_material) convection_terms(c, j, k, cv);

      for (int i = 0; i < nx; ++i) {
        gp[i] = (p0[i] - p1[i]) / h[c] + addG;
        if (need_viscous) {
          // The fluid momentum equation's viscous operator (fluid_solver.cpp), per unit mass.
          const double uP = up[i];
          double lap = 0.0, tstress = 0.0;
          for (const ViscousTerm& T : terms) {
            double tT;
            if (T.kind == ViscousTerm::Kind::along) {
              const double nuf = T.n0[i];
              tT = nuf * (T.u1[i] - T.u0[i]) / h[c];
              lap += nuf * (T.un[i] - uP) / T.h2;
            } else if (T.kind == ViscousTerm::Kind::wall) {
              const double nuf = 0.5 * (T.n0[i] + T.n1[i]);
              if (!T.slip) lap += -2.0 * nuf * uP / T.h2;
              tT = 0.0;  // v = 0 along the wall
            } else {
              const double nuf = 0.25 * (T.n0[i] + T.n1[i] + T.n2[i] + T.n3[i]);
              tT = nuf * (T.u1[i] - T.u0[i]) / h[c];
              lap += nuf * (T.un[i] - uP) / T.h2;
            }
            tstress += T.s * tT / T.hd;
          }
          vs[i] = lap + tstress;
        }
        if (need_material) {
          double conv = 0.0;
          for (int d = 0; d < 3; ++d) {
            const ConvectionTerm& C = cv[d];
            const double ud = d == c ? up[i] : 0.25 * (C.a0[i] + C.a1[i] + C.a2[i] + C.a3[i]);
            const double dudx = (C.b1[i] - C.b0[i]) / (2.0 * h[d]);
            conv += ud * dudx;
          }
          const double dudt_local = first ? 0.0 : (up[i] - uq[i]) / dt_s;
          md[i] = dudt_local + conv;
        }
      }
    }
}

void FluidFields::copy_wall_rows_of_v() {
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  for (int k = kb_; k < ke_; ++k)
    for (int i = 0; i < nx; ++i) {
      const int lo = std::min(1, ny - 1), hi = std::max(ny - 1, 0);
      for (GridField* f : {&gradp_[1], &visc_[1], &dudt_[1]}) {
        f->at(i, 0, k) = f->at(i, lo, k);
        f->at(i, ny, k) = f->at(i, hi, k);
      }
    }
}

}  // namespace boycott::coupling
