#include "coupling/fluid_fields.hpp"

#include <mpi.h>

#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "coupling/slab_exchange.hpp"
#include "fluid/fluid_solver.hpp"

namespace boycott::coupling {

namespace {
constexpr int kE[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}

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

double FluidFields::uval(int c, int i, int j, int k) const {
  if (walls_) {
    const int ny = (int)g_.n[1];
    if (c == 1) {
      if (j < 0) return -u_[1].at(i, -j, k);
      if (j > ny) return -u_[1].at(i, 2 * ny - j, k);
    } else {
      if (j < 0) return -u_[c].at(i, -1 - j, k);
      if (j >= ny) return (top_slip_ ? 1.0 : -1.0) * u_[c].at(i, 2 * ny - 1 - j, k);
    }
  }
  return u_[c].at(i, j, k);
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
  const int n[3] = {(int)g_.n[0], (int)g_.n[1], (int)g_.n[2]};
  const double h[3] = {g_.dx(0), g_.dx(1), g_.dx(2)};

  for (int c = 0; c < 3; ++c) std::swap(u_[c].a, uprev_[c].a);
  // Copy the solver's owned values (one rank: the whole grid); on several ranks the window's
  // other planes come from their owners.
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
  // The planes the fields hold: the whole grid, or the window.
  const int k_first = u_[0].k0, planes = u_[0].nz;
  if (walls_) {
    for (int k = k_first; k < k_first + planes; ++k)
      for (int i = 0; i < n[0]; ++i) u_[1].at(i, 0, k) = u_[1].at(i, n[1], k) = 0.0;
  }
  // Padded copies indexed from plane kofs_; in a window, the pad planes beyond it are never read.
  auto in_window = [&](int k) { return !window_ || (k >= 0 && k < planes); };
  for (int c = 0; c < 3; ++c)
    fill_padded(upad_[c], n[0], u_[c].ny, planes,
                [&](int i, int j, int k) { return in_window(k) ? uval(c, i, j, k + kofs_) : 0.0; });
  // p and nu_t are read inside the walls only (y rows 0 .. ny - 1); their y pads stay unread.
  // Wall mirror two rows out needs ny >= 2 (the fluid grid requires it).
  auto inside = [&](int j, int k) { return (!walls_ || (j >= 0 && j < n[1])) && in_window(k); };
  fill_padded(ppad_, n[0], n[1], planes,
              [&](int i, int j, int k) { return inside(j, k) ? p_.at(i, j, k + kofs_) : 0.0; });
  fill_padded(nupad_, n[0], n[1], planes,
              [&](int i, int j, int k) { return inside(j, k) ? nu_cell(i, j, k + kofs_) : 0.0; });
  // The value at (i + di, j, k) of a padded copy is row(P, j, k)[i + di]: each stencil read below
  // is one row pointer, set once per (j, k) row, plus the cell index; the sums are the same as
  // reading node by node, in the same order.
  auto row = [&](const Padded& P, int j, int k) {
    return P.a.data() +
           (static_cast<std::size_t>(k - kofs_ + Padded::kPad) * P.ny +
            static_cast<std::size_t>(j + Padded::kPad)) *
               P.nx +
           Padded::kPad;
  };
  const bool first = !have_prev_ || dt_s <= 0.0;
  have_prev_ = true;
  const double G = fs.mean_pressure_gradient_pa_m();
  const int nx = n[0];

  // One neighbour term of the viscous operator: the neighbour along d on side s.
  enum class Kind { along, wall, across };
  struct Term {
    Kind kind = Kind::along;
    int s = 1;
    bool slip = false;
    double h2 = 1.0, hd = 1.0;                                                // h_d^2, h_d
    const double *n0 = nullptr, *n1 = nullptr, *n2 = nullptr, *n3 = nullptr;  // nu reads
    const double *u0 = nullptr, *u1 = nullptr, *un = nullptr;                 // velocity reads
  };
  // The reads of the material derivative's term along d.
  struct Conv {
    const double *a0, *a1, *a2, *a3, *b0, *b1;
  };

  for (int c = 0; c < 3; ++c) {
    const int ec[3] = {kE[c][0], kE[c][1], kE[c][2]};
    const int nyc = u_[c].ny;
    const Padded& Uc = upad_[c];
    for (int k = kb_; k < ke_; ++k)
      for (int j = 0; j < nyc; ++j) {
        const bool wall_row = walls_ && c == 1 && (j == 0 || j == n[1]);
        if (wall_row) continue;  // filled from the nearest interior row below
        const int jm = j - ec[1], km = k - ec[2];
        const std::size_t o = (static_cast<std::size_t>(k - u_[c].k0) * nyc + j) * nx;  // (0, j, k), in range
        const double* up = u_[c].a.data() + o;
        const double* uq = uprev_[c].a.data() + o;
        double* gp = gradp_[c].a.data() + o;
        double* vs = visc_[c].a.data() + o;
        double* md = dudt_[c].a.data() + o;
        const double* p0 = row(ppad_, j, k);
        const double* p1 = row(ppad_, jm, km) - ec[0];
        const double addG = c == 2 ? G : 0.0;

        Term terms[6];
        if (need_viscous)
          for (int d = 0, t = 0; d < 3; ++d)
            for (int s = -1; s <= 1; s += 2, ++t) {
              Term& T = terms[t];
              T.s = s, T.h2 = h[d] * h[d], T.hd = h[d];
              const int N[3] = {s * kE[d][0], j + s * kE[d][1], k + s * kE[d][2]};  // i offset, j, k
              if (d == c) {
                T.kind = Kind::along;
                const int Q[3] = {s > 0 ? 0 : -ec[0], s > 0 ? j : jm, s > 0 ? k : km};
                T.n0 = row(nupad_, Q[1], Q[2]) + Q[0];
                T.u0 = row(Uc, Q[1], Q[2]) + Q[0];
                T.u1 = row(Uc, Q[1] + ec[1], Q[2] + ec[2]) + Q[0] + ec[0];
                T.un = row(Uc, N[1], N[2]) + N[0];
                continue;
              }
              const int E[3] = {s > 0 ? N[0] : 0, s > 0 ? N[1] : j, s > 0 ? N[2] : k};
              if (d == 1 && walls_ && (E[1] <= 0 || E[1] >= n[1])) {
                T.kind = Kind::wall;
                T.slip = s > 0 && top_slip_;
                T.n0 = row(nupad_, j, k);
                T.n1 = row(nupad_, jm, km) - ec[0];
                continue;
              }
              T.kind = Kind::across;
              const int O[3] = {E[0] - kE[d][0], E[1] - kE[d][1], E[2] - kE[d][2]};
              T.n0 = row(nupad_, E[1], E[2]) + E[0];
              T.n1 = row(nupad_, E[1] - ec[1], E[2] - ec[2]) + E[0] - ec[0];
              T.n2 = row(nupad_, O[1], O[2]) + O[0];
              T.n3 = row(nupad_, O[1] - ec[1], O[2] - ec[2]) + O[0] - ec[0];
              T.u1 = row(upad_[d], E[1], E[2]) + E[0];
              T.u0 = row(upad_[d], E[1] - ec[1], E[2] - ec[2]) + E[0] - ec[0];
              T.un = row(Uc, N[1], N[2]) + N[0];
            }
        Conv cv[3];
        if (need_material)
          for (int d = 0; d < 3; ++d) {
            const int e[3] = {kE[d][0], kE[d][1], kE[d][2]};
            const Padded& Ud = upad_[d];
            cv[d].a0 = row(Ud, j, k);
            cv[d].a1 = row(Ud, j + e[1], k + e[2]) + e[0];
            cv[d].a2 = row(Ud, jm, km) - ec[0];
            cv[d].a3 = row(Ud, jm + e[1], km + e[2]) - ec[0] + e[0];
            cv[d].b1 = row(Uc, j + e[1], k + e[2]) + e[0];
            cv[d].b0 = row(Uc, j - e[1], k - e[2]) - e[0];
          }

        for (int i = 0; i < nx; ++i) {
          gp[i] = (p0[i] - p1[i]) / h[c] + addG;
          if (need_viscous) {
            // The fluid momentum equation's viscous operator (fluid_solver.cpp), per unit mass.
            const double uP = up[i];
            double lap = 0.0, tstress = 0.0;
            for (const Term& T : terms) {
              double tT;
              if (T.kind == Kind::along) {
                const double nuf = T.n0[i];
                tT = nuf * (T.u1[i] - T.u0[i]) / h[c];
                lap += nuf * (T.un[i] - uP) / T.h2;
              } else if (T.kind == Kind::wall) {
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
              const Conv& C = cv[d];
              const double ud = d == c ? up[i] : 0.25 * (C.a0[i] + C.a1[i] + C.a2[i] + C.a3[i]);
              const double dudx = (C.b1[i] - C.b0[i]) / (2.0 * h[d]);
              conv += ud * dudx;
            }
            const double dudt_local = first ? 0.0 : (up[i] - uq[i]) / dt_s;
            md[i] = dudt_local + conv;
          }
        }
      }
    if (walls_ && c == 1) {
      // Wall rows are not fluid unknowns; a particle near the wall still feels the hydrostatic
      // gradient there, so they take the nearest interior face's value.
      for (int k = kb_; k < ke_; ++k)
        for (int i = 0; i < n[0]; ++i) {
          const int lo = std::min(1, n[1] - 1), hi = std::max(n[1] - 1, 0);
          for (GridField* f : {&gradp_[1], &visc_[1], &dudt_[1]}) {
            f->at(i, 0, k) = f->at(i, lo, k);
            f->at(i, n[1], k) = f->at(i, hi, k);
          }
        }
    }
  }

  if (need_vorticity && edge_vorticity_) update_edge_vorticity();
  if (need_vorticity && !edge_vorticity_) {
    // Cell-centred velocity u_e at (i + di, j + dj, k + dk): sg (A[i] + B[i]) / 2, with the
    // wall mirror rule in y as a sign and a mirrored row (sg = 1 inside: the same value).
    struct CellRow {
      double sg;
      const double *A, *B;
    };
    const int ny = n[1];
    auto cell_row = [&](int e, int di, int jj, int kk) {
      double sg = 1.0;
      if (walls_ && e != 1) {
        if (jj < 0) {
          sg = -1.0, jj = -1 - jj;
        } else if (jj >= ny) {
          sg = top_slip_ ? 1.0 : -1.0, jj = 2 * ny - 1 - jj;
        }
      } else if (walls_ && e == 1 && (jj < 0 || jj >= ny)) {
        sg = -1.0, jj = jj < 0 ? -1 - jj : 2 * ny - 1 - jj;
      }
      return CellRow{sg, row(upad_[e], jj, kk) + di,
                     row(upad_[e], jj + kE[e][1], kk + kE[e][2]) + di + kE[e][0]};
    };
    for (int k = kb_; k < kce_; ++k)
      for (int j = 0; j < ny; ++j) {
        // dd(e, d) = (u_e(+e_d) - u_e(-e_d)) / (2 h_d): rows [e][d][side]
        CellRow r[3][3][2];
        for (int e = 0; e < 3; ++e)
          for (int d = 0; d < 3; ++d)
            if (d != e)
              for (int sd = 0; sd < 2; ++sd) {
                const int s = sd == 0 ? 1 : -1;
                r[e][d][sd] = cell_row(e, s * kE[d][0], j + s * kE[d][1], k + s * kE[d][2]);
              }
        const std::size_t o = (static_cast<std::size_t>(k - vort_[0].k0) * ny + j) * nx;
        double* w0 = vort_[0].a.data() + o;
        double* w1 = vort_[1].a.data() + o;
        double* w2 = vort_[2].a.data() + o;
        for (int i = 0; i < nx; ++i) {
          const auto dd = [&](int e, int d) {
            const CellRow& P = r[e][d][0];
            const CellRow& M = r[e][d][1];
            return (P.sg * (0.5 * (P.A[i] + P.B[i])) - M.sg * (0.5 * (M.A[i] + M.B[i]))) / (2.0 * h[d]);
          };
          w0[i] = dd(2, 1) - dd(1, 2);
          w1[i] = dd(0, 2) - dd(2, 0);
          w2[i] = dd(1, 0) - dd(0, 1);
        }
      }
  }
}

void FluidFields::update_edge_vorticity() {
  // Compact differences of the face velocities with their wall rules (uval: the tangential
  // velocity mirrored beyond a wall, v = 0 on the wall rows), on the planes of the face fields,
  // [kb_, ke_): they are read with face weights in z as those are, and reach one face below.
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const double hx = g_.dx(0), hy = g_.dx(1), hz = g_.dx(2);
  const int nyf = walls_ ? ny + 1 : ny;  // y faces of omega_x and omega_z
  // d(u_c)/dy at the y face j. On a no-slip wall face the mirror's (u_0 + u_0) / h is first
  // order (a parabola's slope is read 8 % low over 6 cells); u = 0 on the wall with the two
  // nearest nodes at h/2 and 3h/2 gives (9 u_0 - u_1) / (3 h), exact for a parabola. A slip wall
  // keeps the mirror's 0.
  auto ddy = [&](int c, int i, int j, int k) {
    if (walls_ && j == 0) return (9.0 * uval(c, i, 0, k) - uval(c, i, 1, k)) / (3.0 * hy);
    if (walls_ && j == ny && !top_slip_)
      return -(9.0 * uval(c, i, ny - 1, k) - uval(c, i, ny - 2, k)) / (3.0 * hy);
    return (uval(c, i, j, k) - uval(c, i, j - 1, k)) / hy;
  };
  for (int k = kb_; k < ke_; ++k) {
    for (int j = 0; j < nyf; ++j)
      for (int i = 0; i < nx; ++i) {
        // omega_x at (i, j - 1/2, k - 1/2) = dw/dy - dv/dz
        vort_[0].at(i, j, k) = ddy(2, i, j, k) - (uval(1, i, j, k) - uval(1, i, j, k - 1)) / hz;
        // omega_z at (i - 1/2, j - 1/2, k) = dv/dx - du/dy
        vort_[2].at(i, j, k) = (uval(1, i, j, k) - uval(1, i - 1, j, k)) / hx - ddy(0, i, j, k);
      }
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        // omega_y at (i - 1/2, j, k - 1/2) = du/dz - dw/dx
        vort_[1].at(i, j, k) =
            (uval(0, i, j, k) - uval(0, i, j, k - 1)) / hz - (uval(2, i, j, k) - uval(2, i - 1, j, k)) / hx;
  }
}

}  // namespace boycott::coupling
