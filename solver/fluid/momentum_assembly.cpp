// Assembly of the momentum equations (fluid_solver.hpp, Eq. 2): face fluxes, effective
// viscosity, and each component's rows (BDF2, QUICK by deferred correction, central
// diffusion with the transpose stress, implicit drag, wall rules) into a StencilOperator.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "fluid/log_events.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/staggering.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

// The momentum rows read each face flux and each viscosity several times (two cells share a
// face, four share an edge); computing them once over the ghosted box costs one pass and took
// the assembly from 44 ms to 27 ms per component on the 200 x 6 x 100 bench mesh (with the flat
// indexing below; writing the values into their matrix slots took it to 10.5 ms).
void FluidSolver::compute_face_fluxes() {
  const LogScope log_scope(fluid_events().fluxes);
  const int n1 = (int)s_.grid.n[1];
  const bool wall = !s_.grid.periodic[1];
  const GhostBox gb = ghost_box();
  PetscScalar ***u[3], ***al, ***F[3];
  BC_PETSC(DMDAVecGetArray(da_, alphal_[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecGetArray(da_, Ul_[d], &u[d]));
    BC_PETSC(DMDAVecGetArray(da_, Fl_[d], &F[d]));
  }
  const int lo[3] = {(int)gb.lo[0], (int)gb.lo[1], (int)gb.lo[2]};
  const int hi[3] = {(int)(gb.lo[0] + gb.size[0]), (int)(gb.lo[1] + gb.size[1]),
                     (int)(gb.lo[2] + gb.size[2])};
  for (int d = 0; d < 3; ++d)
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const int km = k - kE[d][2], jm = j - kE[d][1], im = i - kE[d][0];
          // the lowest ghost layer has no lower neighbour: never read (ghost width 2)
          const bool outside = km < lo[2] || jm < lo[1] || im < lo[0];
          const bool wall_face = wall && d == 1 && (j <= 0 || j >= n1);
          F[d][k][j][i] = (outside || wall_face) ? 0.0 : 0.5 * (al[k][j][i] + al[km][jm][im]) * u[d][k][j][i];
        }
  BC_PETSC(DMDAVecRestoreArray(da_, alphal_[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecRestoreArray(da_, Ul_[d], &u[d]));
    BC_PETSC(DMDAVecRestoreArray(da_, Fl_[d], &F[d]));
  }
}

void FluidSolver::compute_effective_viscosity() {
  BC_PETSC(VecCopy(nutl_, nuel_));
  BC_PETSC(VecShift(nuel_, s_.viscosity_pa_s / s_.density_kg_m3));
}

void FluidSolver::assemble_momentum(int c, double dt, double c0, double c1, double c2, bool first_iteration,
                                    StencilOperator& A) {
  const LogScope log_scope(fluid_events().momentum_assembly);
  // The component, the wall flag and QUICK as compile-time constants: the row loop's branches
  // on them fold away and the neighbour loops unroll (same arithmetic, same bits).
  const bool wall = !s_.grid.periodic[1];
  const auto run = [&](auto C, auto W, auto Q) {
    assemble_momentum_t<decltype(C)::value, decltype(W)::value, decltype(Q)::value>(dt, c0, c1, c2,
                                                                                    first_iteration, A);
  };
  const auto by_flags = [&](auto C) {
    if (wall && s_.quick)
      run(C, std::true_type{}, std::true_type{});
    else if (wall)
      run(C, std::true_type{}, std::false_type{});
    else if (s_.quick)
      run(C, std::false_type{}, std::true_type{});
    else
      run(C, std::false_type{}, std::false_type{});
  };
  if (c == 0)
    by_flags(std::integral_constant<int, 0>{});
  else if (c == 1)
    by_flags(std::integral_constant<int, 1>{});
  else
    by_flags(std::integral_constant<int, 2>{});
}

// The row loop is split by neighbour (loop fission): for one (k, j) row of cells, each of the
// six neighbour terms is a pass over i that GCC vectorises, because every branch of the old
// per-cell code depends on j only (walls) and becomes a row constant, and QUICK's upwind choice
// becomes a select between loads at fixed offsets. Each coefficient is summed in the same order
// as before. The coefficients go to row buffers and from there into the operator's arrays.
template <int c, bool wall, bool use_quick>
void FluidSolver::assemble_momentum_t(double dt, double c0, double c1, double c2, bool first_iteration,
                                      StencilOperator& A) {
  const auto& g = s_.grid;
  const int n1 = (int)g.n[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  const double rho = s_.density_kg_m3;
  const double lam = s_.piso ? 1.0 : s_.velocity_relaxation;  // PISO's sweeps need the unrelaxed equations
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  // Flat views: the triple-pointer DMDA arrays cost three dependent loads per value. Ghosted
  // arrays are indexed by G = (k - gz) sz + (j - gy) gx + (i - gx0), owned ones by o.
  const std::int64_t off[3] = {1, gb.size[0], gb.size[0] * gb.size[1]};
  const std::int64_t oc = off[c];
  const double *u[3], *al[3], *p, *nue, *Fd[3], *un, *unm1, *S, *K, *KU;
  double *rhs, *Dv, *idg;
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(Ul_[d], &u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(Fl_[d], &Fd[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecGetArrayRead(alphal_[l], &al[l]));
  BC_PETSC(VecGetArrayRead(Pl_, &p));
  BC_PETSC(VecGetArrayRead(nuel_, &nue));
  BC_PETSC(VecGetArrayRead(flow_.Un[c], &un));
  BC_PETSC(VecGetArrayRead(flow_.Unm1[c], &unm1));
  BC_PETSC(VecGetArrayRead(S_[c], &S));
  BC_PETSC(VecGetArrayRead(K_[c], &K));
  BC_PETSC(VecGetArrayRead(KU_[c], &KU));
  BC_PETSC(VecGetArray(rhs_, &rhs));
  BC_PETSC(VecGetArray(D_[c], &Dv));
  BC_PETSC(VecGetArray(inv_diag_[c], &idg));
  double* Ae[7];
  for (int e = 0; e < 7; ++e) Ae[e] = A.coef(e);

  const double* __restrict uc = u[c];
  const double* __restrict nu = nue;
  // v = 0 on the y walls (j = 0 and j = ny): a u_c node in y-row jx is a known zero
  auto zero_node = [&](int jx) -> bool { return c == 1 && wall && (jx <= 0 || jx >= n1); };
  // face node in y-row jx is inside the domain (QUICK's far upwind node may not be)
  auto face_ok = [&](int jx) -> bool {
    if (!wall) return true;
    return c == 1 ? (jx >= 0 && jx <= n1) : (jx >= 0 && jx <= n1 - 1);
  };
  const double body = s_.body_acceleration_m_s2[c] - (c == 2 ? flow_.G_pa_m / rho : 0.0);
  const double ih[3] = {1.0 / h[0], 1.0 / h[1], 1.0 / h[2]};
  const double ih2[3] = {ih[0] * ih[0], ih[1] * ih[1], ih[2] * ih[2]};
  const double inv_dt = 1.0 / dt, inv_rho = 1.0 / rho, inv_lam = 1.0 / lam;
  const bool top_slip = s_.top_slip;

  // row buffers: a_P, right-hand side, a_face, transpose stress, sum |a_nb|, 6 neighbour coefficients
  const int nx = (int)b.size[0];
  row_buffers_.assign(static_cast<std::size_t>(11) * nx, 0.0);
  double* __restrict aP = row_buffers_.data();
  double* __restrict bb = aP + nx;
  double* __restrict a1v = bb + nx;
  double* __restrict ts = a1v + nx;
  double* __restrict snb = ts + nx;
  double* anb[7] = {nullptr};
  for (int e = 1; e < 7; ++e) anb[e] = snb + e * nx;

  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * off[2] + (j - gb.lo[1]) * off[1] + (b.lo[0] - gb.lo[0]);
      if (c == 1 && wall && j == 0) {  // v = 0 on the wall itself: an identity row
        for (int e = 0; e < 7; ++e) std::fill(Ae[e] + o0, Ae[e] + o0 + nx, e == 0 ? 1.0 : 0.0);
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          idg[o0 + i] = 1.0;
          rhs[o0 + i] = 0.0;
          if (first_iteration) Dv[o0 + i] = 0.0;
        }
        continue;
      }
      {  // time derivative, drag, pressure gradient, body force and sources
        const double* __restrict a0 = al[0] + P0, * __restrict an = al[1] + P0, * __restrict anm = al[2] + P0;
        const double* __restrict pp = p + P0, * __restrict Ko = K + o0, * __restrict uno = un + o0;
        const double* __restrict unmo = unm1 + o0, * __restrict So = S + o0, * __restrict KUo = KU + o0;
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const double a1 = 0.5 * (a0[i] + a0[i - oc]);
          const double a_n = 0.5 * (an[i] + an[i - oc]);
          const double a_nm1 = 0.5 * (anm[i] + anm[i - oc]);
          aP[i] = c0 * a1 * inv_dt + Ko[i] * inv_rho;
          double b_ = (c1 * a_n * uno[i] - c2 * a_nm1 * unmo[i]) * inv_dt;
          b_ += a1 * body - a1 * (pp[i] - pp[i - oc]) * (inv_rho * ih[c]);
          b_ += (So[i] + KUo[i]) * inv_rho;
          bb[i] = b_;
          a1v[i] = a1;
          ts[i] = 0.0;
          snb[i] = 0.0;
        }
      }
      unsigned present = 1u;  // bit e: entry e of these rows is written
      for (int d = 0; d < 3; ++d) {
        const std::int64_t od = off[d];
        for (int s = -1; s <= 1; s += 2) {
          const int e = 1 + 2 * d + (s > 0);
          const int jN = j + s * kE[d][1];
          // face flux, viscosity and transpose-stress reads of this neighbour, as offsets from P
          std::int64_t fo;             // first flux node (the second is fo - oc or fo + oc)
          bool nb_known_zero = false;  // neighbour is a wall value v = 0 (not an unknown)
          if (d != c) {
            const int jE = s > 0 ? jN : j;  // the d-face of cell E = P + e_d (s > 0) or P
            if (d == 1 && wall && (jE <= 0 || jE >= n1)) {
              // u_c = 0 on the wall half a cell away (no-slip), or no stress (slip top); v = 0
              // there, so the transpose stress term vanishes
              if (!(s > 0 && top_slip)) {
                const double* __restrict nP = nu + P0;
#pragma GCC ivdep
                for (int i = 0; i < nx; ++i) {
                  const double nuf = 0.5 * (nP[i] + nP[i - oc]);
                  aP[i] += 2.0 * a1v[i] * nuf * ih2[d];
                }
              }
              continue;
            }
            fo = s > 0 ? od : 0;
          } else {
            fo = s > 0 ? 0 : -oc;  // face at the cell centre Q = P or P - e_c
            nb_known_zero = zero_node(jN);
          }
          // QUICK: the upwind node is P (conv > 0) or N; its far node is P - s e_d or N + s e_d.
          // Row constants say which of those nodes exist and which are wall zeros; reads of a
          // node that does not exist or is a wall zero (v at j = ny lies outside the ghosted
          // box) are redirected to P and their value is multiplied by zero.
          const bool okN = face_ok(jN);
          const bool ok_up = face_ok(j - s * kE[d][1]) && face_ok(j) && okN;
          const bool ok_dn = face_ok(j + 2 * s * kE[d][1]) && face_ok(j) && okN;
          const double zP = zero_node(j) ? 0.0 : 1.0, zN = zero_node(jN) ? 0.0 : 1.0;
          const double zUu = zero_node(j - s * kE[d][1]) ? 0.0 : 1.0,
                       zUd = zero_node(j + 2 * s * kE[d][1]) ? 0.0 : 1.0;
          const double qup = ok_up ? 1.0 : 0.0, qdn = ok_dn ? 1.0 : 0.0;
          const std::int64_t oN = okN && zN != 0.0 ? s * od : 0;
          const std::int64_t oUu = ok_up && zUu != 0.0 ? -s * od : 0,
                             oUd = ok_dn && zUd != 0.0 ? 2 * s * od : 0;
          double* __restrict ae = anb[e];
          const double* __restrict uP_ = uc + P0;
          const double sh = s * 0.5;
          const double ihd = ih[d], ih2d = ih2[d], ihc = ih[c];
          if (!nb_known_zero) present |= 1u << e;
          // a weight, not a select on nb_known_zero: GCC 12 does not vectorise a select on a
          // loop-invariant bool, which left v's neighbour passes scalar (3x u's assembly time)
          const double w_nb = nb_known_zero ? 0.0 : 1.0;
          const auto tail = [&](int i, double F, double nuf, double tT) {
            ts[i] += s * tT * ih[d];
            const double dcoef = a1v[i] * nuf * ih2d;
            const double conv = F * ihd;
            aP[i] += dcoef + std::max(conv, 0.0);
            const double a = -dcoef + std::min(conv, 0.0);
            ae[i] = a;
            snb[i] += w_nb * std::abs(a);
            if constexpr (use_quick) {
              // rhs -= F (phi_QUICK - phi_upwind) / h, deferred correction
              const double vP = zP * uP_[i], vN = zN * uP_[i + oN];
              const double vUu = zUu * uP_[i + oUu], vUd = zUd * uP_[i + oUd];
              const bool up = conv > 0.0;
              const double pc = up ? vP : vN, pd = up ? vN : vP, pu = up ? vUu : vUd;
              const double ok = up ? qup : qdn;
              const double quick = 0.75 * pc + 0.375 * pd - 0.125 * pu;
              bb[i] -= ok * (conv * (quick - pc));
            }
          };
          if (d == c) {
            const double* __restrict F0 = Fd[c] + P0 + fo;
            const double* __restrict nQ = nu + P0 + fo;
            const double* __restrict uQ = uc + P0 + fo;
            const double zlo = zero_node(s > 0 ? j : j - kE[c][1]) ? 0.0 : 1.0;
            const double zhi = zero_node(s > 0 ? j + kE[c][1] : j) ? 0.0 : 1.0;
            const std::int64_t ohi = zhi != 0.0 ? oc : 0;  // v at j = ny is outside the ghosted box
#pragma GCC ivdep
            for (int i = 0; i < nx; ++i) {
              const double F = sh * (F0[i] + F0[i + oc]);
              const double nuf = nQ[i];
              const double tT = nuf * (zhi * uQ[i + ohi] - zlo * uQ[i]) * ihc;
              tail(i, F, nuf, tT);
            }
          } else {
            const double* __restrict FE = Fd[d] + P0 + fo;
            const double* __restrict nE = nu + P0 + fo;
            const double* __restrict uE = u[d] + P0 + fo;
#pragma GCC ivdep
            for (int i = 0; i < nx; ++i) {
              const double F = sh * (FE[i] + FE[i - oc]);
              const double nuf = 0.25 * (nE[i] + nE[i - oc] + nE[i - od] + nE[i - oc - od]);
              const double tT = nuf * (uE[i] - uE[i - oc]) * ihc;
              tail(i, F, nuf, tT);
            }
          }
        }
      }
      {
        const double* __restrict uP_ = uc + P0;
        double* __restrict rh = rhs + o0, * __restrict Dd = Dv + o0;
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) {
          const double b_ = bb[i] + a1v[i] * ts[i];
          const double aPr = aP[i] * inv_lam;
          rh[i] = b_ + (aPr - aP[i]) * uP_[i];
          aP[i] = aPr;
        }
        // SIMPLEC (Van Doormaal and Raithby 1984): u' = -(a/(rho (a_P - sum a_nb))) grad p'.
        // SIMPLE's a/(rho a_P) diverges for diffusion-dominated cells of high aspect ratio
        // (nu dt/h_y^2 >> 1 with h_x >> h_y, as on the paper's 1 mm grid with 6 cells across a
        // 6 mm gap).
        if (first_iteration)
#pragma GCC ivdep
          for (int i = 0; i < nx; ++i) Dd[i] = a1v[i] / (rho * (aP[i] - snb[i]));
        double* __restrict id = idg + o0;
#pragma GCC ivdep
        for (int i = 0; i < nx; ++i) id[i] = 1.0 / aP[i];
      }
      // entries of known zeros (wall values v = 0, no-slip faces) are stored as 0
      std::copy(aP, aP + nx, Ae[0] + o0);
      for (int e = 1; e < 7; ++e)
        if (present >> e & 1u)
          std::copy(anb[e], anb[e] + nx, Ae[e] + o0);
        else
          std::fill(Ae[e] + o0, Ae[e] + o0 + nx, 0.0);
    }

  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(Ul_[d], &u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(Fl_[d], &Fd[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecRestoreArrayRead(alphal_[l], &al[l]));
  BC_PETSC(VecRestoreArrayRead(Pl_, &p));
  BC_PETSC(VecRestoreArrayRead(nuel_, &nue));
  BC_PETSC(VecRestoreArrayRead(flow_.Un[c], &un));
  BC_PETSC(VecRestoreArrayRead(flow_.Unm1[c], &unm1));
  BC_PETSC(VecRestoreArrayRead(S_[c], &S));
  BC_PETSC(VecRestoreArrayRead(K_[c], &K));
  BC_PETSC(VecRestoreArrayRead(KU_[c], &KU));
  BC_PETSC(VecRestoreArray(rhs_, &rhs));
  BC_PETSC(VecRestoreArray(D_[c], &Dv));
  BC_PETSC(VecRestoreArray(inv_diag_[c], &idg));
}

}  // namespace boycott::fluid
