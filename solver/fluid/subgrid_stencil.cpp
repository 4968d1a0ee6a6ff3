// The velocity-gradient stencil of the Vreman subgrid model (vreman.hpp holds the model): nu_t
// per cell from the staggered velocities, with the wall rules of each component.
#include "fluid/fluid_solver.hpp"

#include <array>
#include <cstdint>

#include "fluid/halo_exchange.hpp"
#include "fluid/log_events.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/staggering.hpp"
#include "fluid/vreman.hpp"

namespace boycott::fluid {

namespace {

/// The grid as the gradient stencil sees it.
struct GradientGrid {
  int n1 = 0, nx = 0;  // y cells; x cells of a row
  double h[3] = {};    // cell sizes, m
  std::int64_t off[3] = {};
  bool wall = false, top_slip = false;
  /// u_c at y-row jx is a known zero (v on the y walls); reads there are redirected to P.
  bool zero(int c, int jx) const { return c == 1 && wall && (jx <= 0 || jx >= n1); }
};

/// d u_jc / d x_jc over the row: (z_hi u[hi] - z_lo u[lo]) / h, z 0 at a known zero.
[[gnu::always_inline]] inline void diagonal_gradient(const GradientGrid& g, int jc, int j,
                                                     const double* __restrict uc, double* __restrict out) {
  const double zh = g.zero(jc, j + kE[jc][1]) ? 0.0 : 1.0, zl = g.zero(jc, j) ? 0.0 : 1.0;
  const std::int64_t oh = zh != 0.0 ? g.off[jc] : 0;
  const double hc = g.h[jc];
#pragma GCC ivdep
  for (int i = 0; i < g.nx; ++i) out[i] = (zh * uc[i + oh] - zl * uc[i]) / hc;
}

/// d u_jc / d x_id (id != jc) averaged over the four edges of the cell in the (id, jc) plane:
/// term t = (a, s) is (f_hi u[hi] - f_lo u[lo]) / den, with f, den and the offsets row constants.
struct EdgeTerms {
  double fh[4], fl[4], den[4];
  std::int64_t oh[4], ol[4];
};

EdgeTerms edge_terms(const GradientGrid& g, int jc, int id, int j) {
  EdgeTerms e;
  for (int a = 0; a < 2; ++a)
    for (int s = 0; s < 2; ++s) {
      const int t = 2 * a + s;
      const std::int64_t qo = a * g.off[jc];  // Q = P + a e_jc
      const int qj = j + a * kE[jc][1];
      std::int64_t lo = qo - (s == 0) * g.off[id], hi = lo + g.off[id];
      int jlo = qj - (s == 0) * kE[id][1], jhi = jlo + kE[id][1];
      e.fh[t] = 1.0, e.fl[t] = 1.0, e.den[t] = g.h[id];
      if (id == 1 && g.wall) {
        // one-sided at the walls: u_jc = 0 (no-slip) or zero gradient (slip top)
        if (jlo < 0) {
          e.fl[t] = 0.0, e.den[t] = 0.5 * g.h[1];
        } else if (jhi > g.n1 - 1) {
          e.fh[t] = 0.0, e.den[t] = 0.5 * g.h[1];
          if (g.top_slip) e.fl[t] = 0.0;
        }
      }
      if (g.zero(jc, jhi)) e.fh[t] = 0.0;
      if (g.zero(jc, jlo)) e.fl[t] = 0.0;
      e.oh[t] = e.fh[t] != 0.0 ? hi : 0;
      e.ol[t] = e.fl[t] != 0.0 ? lo : 0;
    }
  return e;
}

[[gnu::always_inline]] inline void edge_gradient(const EdgeTerms& e, int nx, const double* __restrict uc,
                                                 double* __restrict out) {
  const double *fh = e.fh, *fl = e.fl, *den = e.den;
  const std::int64_t *oh = e.oh, *ol = e.ol;
#pragma GCC ivdep
  for (int i = 0; i < nx; ++i) {
    double sum = 0.0;
    for (int t = 0; t < 4; ++t) sum += (fh[t] * uc[i + oh[t]] - fl[t] * uc[i + ol[t]]) / den[t];
    out[i] = 0.25 * sum;
  }
}

/// Vreman's nu_t of the row from its gradient G[i][j] = d u_j / d x_i.
[[gnu::always_inline]] inline void vreman_row(double* const (&G)[3][3], const std::array<double, 3>& delta,
                                              double cv, int nx, double* __restrict nto) {
#pragma GCC ivdep
  for (int i = 0; i < nx; ++i) {
    const std::array<std::array<double, 3>, 3> grad = {{{G[0][0][i], G[0][1][i], G[0][2][i]},
                                                        {G[1][0][i], G[1][1][i], G[1][2][i]},
                                                        {G[2][0][i], G[2][1][i], G[2][2][i]}}};
    nto[i] = vreman_viscosity(grad, delta, cv);
  }
}

}  // namespace

// The gradient is formed one (k, j) row of cells at a time in passes over i that GCC vectorises:
// every wall rule depends on j only, so it becomes a row constant (a coefficient and an offset
// per term), and the sums keep the order of the cell-by-cell form they replaced (same bits).
void FluidSolver::compute_subgrid_viscosity() {
  const LogScope log_scope(fluid_events().subgrid);
  if (!s_.vreman) {
    BC_PETSC(VecZeroEntries(flow_.nut));
    layout_.halo->fill(flow_.nut, ghosts_.nut);
    return;
  }
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  GradientGrid gg;
  gg.n1 = (int)s_.grid.n[1], gg.nx = (int)b.size[0];
  for (int d = 0; d < 3; ++d) gg.h[d] = s_.grid.dx(d);
  gg.off[0] = 1, gg.off[1] = gb.size[0], gg.off[2] = gb.size[0] * gb.size[1];
  gg.wall = !s_.grid.periodic[1], gg.top_slip = s_.top_slip;
  const std::array<double, 3> delta = {gg.h[0], gg.h[1], gg.h[2]};
  const double* u[3];
  double* nt;
  for (int c = 0; c < 3; ++c) BC_PETSC(VecGetArrayRead(ghosts_.U[c], &u[c]));
  BC_PETSC(VecGetArray(flow_.nut, &nt));
  const int nx = gg.nx;
  work_.row_buffers.assign(static_cast<std::size_t>(9) * nx, 0.0);
  double* G[3][3];  // G[i][j] = d u_j / d x_i over the row
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) G[i][j] = work_.row_buffers.data() + (3 * i + j) * nx;
  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * gg.off[2] + (j - gb.lo[1]) * gg.off[1] + (b.lo[0] - gb.lo[0]);
      for (int jc = 0; jc < 3; ++jc) {
        diagonal_gradient(gg, jc, j, u[jc] + P0, G[jc][jc]);
        for (int id = 0; id < 3; ++id)
          if (id != jc) edge_gradient(edge_terms(gg, jc, id, j), nx, u[jc] + P0, G[id][jc]);
      }
      vreman_row(G, delta, s_.vreman_constant, nx, nt + o0);
    }
  for (int c = 0; c < 3; ++c) BC_PETSC(VecRestoreArrayRead(ghosts_.U[c], &u[c]));
  BC_PETSC(VecRestoreArray(flow_.nut, &nt));
  layout_.halo->fill(flow_.nut, ghosts_.nut);
}

}  // namespace boycott::fluid
