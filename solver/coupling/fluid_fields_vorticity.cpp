// The vorticity FluidFields derives for the lift: at cell centres from the cell-centred
// velocity, or at the grid's edges by compact differences (fluid_fields.hpp says where each
// component lives and why).
#include "coupling/fluid_fields.hpp"
#include "fluid/staggering.hpp"

namespace boycott::coupling {

using fluid::kE;

void FluidFields::update_centre_vorticity() {
  // Cell-centred velocity u_e at (i + di, j + dj, k + dk): sg (A[i] + B[i]) / 2, with the
  // wall mirror rule in y as a sign and a mirrored row (sg = 1 inside: the same value).
  struct CellRow {
    double sg;
    const double *A, *B;
  };
  const int nx = (int)g_.n[0], ny = (int)g_.n[1];
  const double h[3] = {g_.dx(0), g_.dx(1), g_.dx(2)};
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
    return CellRow{sg, padded_row(upad_[e], jj, kk) + di,
                   padded_row(upad_[e], jj + kE[e][1], kk + kE[e][2]) + di + kE[e][0]};
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
