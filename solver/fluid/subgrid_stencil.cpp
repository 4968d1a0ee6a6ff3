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

// The gradient is formed one (k, j) row of cells at a time in passes over i that GCC vectorises:
// every wall rule depends on j only, so it becomes a row constant (a coefficient and an offset
// per term), and the sums keep the order of the cell-by-cell form they replaced (same bits).
void FluidSolver::compute_subgrid_viscosity() {
  const LogScope log_scope(fluid_events().subgrid);
  if (!s_.vreman) {
    BC_PETSC(VecZeroEntries(flow_.nut));
    halo_->fill(flow_.nut, nutl_);
    return;
  }
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const bool wall = !g.periodic[1];
  const std::array<double, 3> delta = {h[0], h[1], h[2]};
  const double cv = s_.vreman_constant;
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const double* u[3];
  double* nt;
  for (int c = 0; c < 3; ++c) BC_PETSC(VecGetArrayRead(Ul_[c], &u[c]));
  BC_PETSC(VecGetArray(flow_.nut, &nt));
  const int nx = (int)b.size[0];
  row_buffers_.assign(static_cast<std::size_t>(9) * nx, 0.0);
  double* G[3][3];  // G[i][j] = d u_j / d x_i over the row
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) G[i][j] = row_buffers_.data() + (3 * i + j) * nx;
  // u_c at y-row jx is a known zero (v on the y walls); reads there are redirected to P
  auto zero = [&](int c, int jx) { return c == 1 && wall && (jx <= 0 || jx >= n1); };
  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
      for (int jc = 0; jc < 3; ++jc) {
        const double* __restrict uc = u[jc] + P0;
        {  // d u_jc / d x_jc
          const double zh = zero(jc, j + kE[jc][1]) ? 0.0 : 1.0, zl = zero(jc, j) ? 0.0 : 1.0;
          const std::int64_t oh = zh != 0.0 ? off[jc] : 0;
          const double hc = h[jc];
          double* __restrict out = G[jc][jc];
#pragma GCC ivdep
          for (int i = 0; i < nx; ++i) out[i] = (zh * uc[i + oh] - zl * uc[i]) / hc;
        }
        for (int id = 0; id < 3; ++id) {
          if (id == jc) continue;
          // d u_jc / d x_id averaged over the four edges of the cell in the (id, jc) plane:
          // term (a, s) = (f_hi u[hi] - f_lo u[lo]) / den, f and den row constants
          double fh[4], fl[4], den[4];
          std::int64_t oh[4], ol[4];
          for (int a = 0; a < 2; ++a)
            for (int s = 0; s < 2; ++s) {
              const int t = 2 * a + s;
              const std::int64_t qo = a * off[jc];  // Q = P + a e_jc
              const int qj = j + a * kE[jc][1];
              std::int64_t lo = qo - (s == 0) * off[id], hi = lo + off[id];
              int jlo = qj - (s == 0) * kE[id][1], jhi = jlo + kE[id][1];
              fh[t] = 1.0, fl[t] = 1.0, den[t] = h[id];
              if (id == 1 && wall) {
                // one-sided at the walls: u_jc = 0 (no-slip) or zero gradient (slip top)
                if (jlo < 0) {
                  fl[t] = 0.0, den[t] = 0.5 * h[1];
                } else if (jhi > n1 - 1) {
                  fh[t] = 0.0, den[t] = 0.5 * h[1];
                  if (s_.top_slip) fl[t] = 0.0;
                }
              }
              if (zero(jc, jhi)) fh[t] = 0.0;
              if (zero(jc, jlo)) fl[t] = 0.0;
              oh[t] = fh[t] != 0.0 ? hi : 0;
              ol[t] = fl[t] != 0.0 ? lo : 0;
            }
          double* __restrict out = G[id][jc];
#pragma GCC ivdep
          for (int i = 0; i < nx; ++i) {
            double sum = 0.0;
            for (int t = 0; t < 4; ++t) sum += (fh[t] * uc[i + oh[t]] - fl[t] * uc[i + ol[t]]) / den[t];
            out[i] = 0.25 * sum;
          }
        }
      }
      double* __restrict nto = nt + o0;
#pragma GCC ivdep
      for (int i = 0; i < nx; ++i) {
        const std::array<std::array<double, 3>, 3> grad = {{{G[0][0][i], G[0][1][i], G[0][2][i]},
                                                            {G[1][0][i], G[1][1][i], G[1][2][i]},
                                                            {G[2][0][i], G[2][1][i], G[2][2][i]}}};
        nto[i] = vreman_viscosity(grad, delta, cv);
      }
    }
  for (int c = 0; c < 3; ++c) BC_PETSC(VecRestoreArrayRead(Ul_[c], &u[c]));
  BC_PETSC(VecRestoreArray(flow_.nut, &nt));
  halo_->fill(flow_.nut, nutl_);
}

}  // namespace boycott::fluid
