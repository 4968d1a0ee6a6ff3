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

FluidFields::FluidFields(const GridSpec& g, bool top_slip, const SlabExchange* window)
    : g_(g), walls_(!g.periodic[1]), top_slip_(top_slip), window_(window) {
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
    vort_[c].resize(nx, ny, nz, per, k0);
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
  const Padded* const U[3] = {&upad_[0], &upad_[1], &upad_[2]};
  auto uv = [&](int c, int i, int j, int k) { return (*U[c])(i, j, k - kofs_); };
  auto nuc = [&](int i, int j, int k) { return nupad_(i, j, k - kofs_); };
  const bool first = !have_prev_ || dt_s <= 0.0;
  have_prev_ = true;
  const double G = fs.mean_pressure_gradient_pa_m();

  for (int c = 0; c < 3; ++c) {
    const int ec[3] = {kE[c][0], kE[c][1], kE[c][2]};
    const int nyc = u_[c].ny;
    for (int k = kb_; k < ke_; ++k)
      for (int j = 0; j < nyc; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const bool wall_row = walls_ && c == 1 && (j == 0 || j == n[1]);
          if (wall_row) continue;  // filled from the nearest interior row below
          const int im = i - ec[0], jm = j - ec[1], km = k - ec[2];
          gradp_[c].at(i, j, k) =
              (ppad_(i, j, k - kofs_) - ppad_(im, jm, km - kofs_)) / h[c] + (c == 2 ? G : 0.0);

          if (need_viscous) {
            // The fluid momentum equation's viscous operator (fluid_solver.cpp), per unit mass.
            const double uP = u_[c].at(i, j, k);
            double lap = 0.0, tstress = 0.0;
            for (int d = 0; d < 3; ++d)
              for (int s = -1; s <= 1; s += 2) {
                const int N[3] = {i + s * kE[d][0], j + s * kE[d][1], k + s * kE[d][2]};
                double nuf = 0.0, tT = 0.0;
                if (d == c) {
                  const int Q[3] = {s > 0 ? i : im, s > 0 ? j : jm, s > 0 ? k : km};
                  nuf = nuc(Q[0], Q[1], Q[2]);
                  tT = nuf * (uv(c, Q[0] + ec[0], Q[1] + ec[1], Q[2] + ec[2]) - uv(c, Q[0], Q[1], Q[2])) /
                       h[c];
                  lap += nuf * (uv(c, N[0], N[1], N[2]) - uP) / (h[d] * h[d]);
                } else {
                  const int E[3] = {s > 0 ? N[0] : i, s > 0 ? N[1] : j, s > 0 ? N[2] : k};
                  if (d == 1 && walls_ && (E[1] <= 0 || E[1] >= n[1])) {
                    nuf = 0.5 * (nuc(i, j, k) + nuc(im, jm, km));
                    const bool slip = s > 0 && top_slip_;
                    if (!slip) lap += -2.0 * nuf * uP / (h[d] * h[d]);
                    tT = 0.0;  // v = 0 along the wall
                  } else {
                    const int O[3] = {E[0] - kE[d][0], E[1] - kE[d][1], E[2] - kE[d][2]};
                    nuf = 0.25 * (nuc(E[0], E[1], E[2]) + nuc(E[0] - ec[0], E[1] - ec[1], E[2] - ec[2]) +
                                  nuc(O[0], O[1], O[2]) + nuc(O[0] - ec[0], O[1] - ec[1], O[2] - ec[2]));
                    tT = nuf * (uv(d, E[0], E[1], E[2]) - uv(d, E[0] - ec[0], E[1] - ec[1], E[2] - ec[2])) /
                         h[c];
                    lap += nuf * (uv(c, N[0], N[1], N[2]) - uP) / (h[d] * h[d]);
                  }
                }
                tstress += s * tT / h[d];
              }
            visc_[c].at(i, j, k) = lap + tstress;
          }

          if (need_material) {
            double conv = 0.0;
            for (int d = 0; d < 3; ++d) {
              double ud;
              if (d == c) {
                ud = u_[c].at(i, j, k);
              } else {
                const int e[3] = {kE[d][0], kE[d][1], kE[d][2]};
                ud = 0.25 * (uv(d, i, j, k) + uv(d, i + e[0], j + e[1], k + e[2]) + uv(d, im, jm, km) +
                             uv(d, im + e[0], jm + e[1], km + e[2]));
              }
              const double dudx = (uv(c, i + kE[d][0], j + kE[d][1], k + kE[d][2]) -
                                   uv(c, i - kE[d][0], j - kE[d][1], k - kE[d][2])) /
                                  (2.0 * h[d]);
              conv += ud * dudx;
            }
            const double dudt_local = first ? 0.0 : (u_[c].at(i, j, k) - uprev_[c].at(i, j, k)) / dt_s;
            dudt_[c].at(i, j, k) = dudt_local + conv;
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

  if (need_vorticity) {
    // Cell-centred velocity with the wall mirror rule, then central differences.
    auto uc = [&](int e, int i, int j, int k) {
      return 0.5 * (uv(e, i, j, k) + uv(e, i + kE[e][0], j + kE[e][1], k + kE[e][2]));
    };
    auto ucell = [&](int e, int i, int j, int k) {
      if (walls_ && e != 1) {
        if (j < 0) return -uc(e, i, -1 - j, k);
        if (j >= n[1]) return (top_slip_ ? 1.0 : -1.0) * uc(e, i, 2 * n[1] - 1 - j, k);
      }
      if (walls_ && e == 1 && (j < 0 || j >= n[1])) return -uc(e, i, j < 0 ? -1 - j : 2 * n[1] - 1 - j, k);
      return uc(e, i, j, k);
    };
    auto dd = [&](int e, int d, int i, int j, int k) {
      return (ucell(e, i + kE[d][0], j + kE[d][1], k + kE[d][2]) -
              ucell(e, i - kE[d][0], j - kE[d][1], k - kE[d][2])) /
             (2.0 * h[d]);
    };
    for (int k = kb_; k < kce_; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          vort_[0].at(i, j, k) = dd(2, 1, i, j, k) - dd(1, 2, i, j, k);
          vort_[1].at(i, j, k) = dd(0, 2, i, j, k) - dd(2, 0, i, j, k);
          vort_[2].at(i, j, k) = dd(1, 0, i, j, k) - dd(0, 1, i, j, k);
        }
  }
}

}  // namespace boycott::coupling
