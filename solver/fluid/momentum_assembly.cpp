// Assembly of the momentum equations (fluid_solver.hpp, Eq. 2): face fluxes, effective
// viscosity, and each component's rows (BDF2, QUICK by deferred correction, central
// diffusion with the transpose stress, implicit drag, wall rules) into a StencilOperator.
#include "fluid/fluid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "fluid/log_events.hpp"
#include "fluid/petsc_check.hpp"
#include "fluid/staggering.hpp"
#include "fluid/stencil_operator.hpp"

namespace boycott::fluid {

namespace {

/// One component's momentum rows read and write these arrays as flat views: the triple-pointer
/// DMDA arrays cost three dependent loads per value. Ghosted arrays are indexed by
/// G = (k - gz) sz + (j - gy) gx + (i - gx0), owned ones by o.
struct MomentumArrays {
  const double *u[3], *F[3], *alpha[3];  // velocity, face flux, fluid fraction at n+1, n, n-1 (ghosted)
  const double *p, *nue;                 // pressure, nu + nu_t (ghosted)
  const double *un, *unm1, *S, *K, *KU;  // component c at n and n-1, coupling sources (owned)
  double *rhs, *D, *inv_diag;            // right-hand side, SIMPLEC coefficient, 1 / a_P (owned)
  double* A[7];                          // the operator's coefficients, entry e of each row
};

/// What every row of one assembly shares: the grid and the BDF2, relaxation and body terms.
struct MomentumConstants {
  int n1 = 0, nx = 0;               // y cells; x cells of a row
  std::int64_t off[3] = {0, 0, 0};  // strides of the ghosted arrays
  double ih[3] = {}, ih2[3] = {};   // 1/h, 1/h^2 per direction, 1/m, 1/m^2
  double rho_kg_m3 = 0.0, inv_rho = 0.0;
  double c0 = 0.0, c1 = 0.0, c2 = 0.0;  // BDF2 weights
  double inv_dt = 0.0, inv_lam = 0.0;   // 1/s; 1 / velocity under-relaxation
  double body_m_s2 = 0.0;               // body acceleration of component c, the mean gradient G included
  bool top_slip = false, first_iteration = false;
};

/// The row buffers (11 nx values): a_P, right-hand side, a_face, transpose stress, sum |a_nb|,
/// then the 6 neighbour coefficients anb[1..6].
struct RowBuffers {
  double *aP, *b, *a1, *ts, *snb;
  double* anb[7];
  RowBuffers(std::vector<double>& buf, int nx) {
    buf.assign(static_cast<std::size_t>(11) * nx, 0.0);
    aP = buf.data(), b = aP + nx, a1 = b + nx, ts = a1 + nx, snb = ts + nx;
    anb[0] = nullptr;
    for (int e = 1; e < 7; ++e) anb[e] = snb + e * nx;
  }
};

/// v = 0 on the y walls (j = 0 and j = ny): a u_c node in y-row jx is a known zero.
template <int c, bool wall>
constexpr bool zero_node(int jx, int n1) {
  return c == 1 && wall && (jx <= 0 || jx >= n1);
}

/// The face node in y-row jx is inside the domain (QUICK's far upwind node may not be).
template <int c, bool wall>
constexpr bool face_ok(int jx, int n1) {
  if (!wall) return true;
  return c == 1 ? (jx >= 0 && jx <= n1) : (jx >= 0 && jx <= n1 - 1);
}

/// v = 0 on the wall itself (c = 1, j = 0): an identity row.
[[gnu::always_inline]] inline void identity_row(const MomentumArrays& m, const MomentumConstants& k,
                                                std::int64_t o0) {
  const int nx = k.nx;
  for (int e = 0; e < 7; ++e) std::fill(m.A[e] + o0, m.A[e] + o0 + nx, e == 0 ? 1.0 : 0.0);
#pragma GCC ivdep
  for (int i = 0; i < nx; ++i) {
    m.inv_diag[o0 + i] = 1.0;
    m.rhs[o0 + i] = 0.0;
    if (k.first_iteration) m.D[o0 + i] = 0.0;
  }
}

/// Time derivative, drag, pressure gradient, body force and sources: the row's start.
template <int c>
[[gnu::always_inline]] inline void local_terms(const MomentumArrays& m, const MomentumConstants& k,
                                               const RowBuffers& r, std::int64_t P0, std::int64_t o0) {
  const std::int64_t oc = k.off[c];
  const double c0 = k.c0, c1 = k.c1, c2 = k.c2, inv_dt = k.inv_dt, inv_rho = k.inv_rho, body = k.body_m_s2;
  const double ihc = k.ih[c];
  double* __restrict aP = r.aP;
  double* __restrict bb = r.b;
  double* __restrict a1v = r.a1;
  double* __restrict ts = r.ts;
  double* __restrict snb = r.snb;
  const double* __restrict a0 = m.alpha[0] + P0;
  const double* __restrict an = m.alpha[1] + P0;
  const double* __restrict anm = m.alpha[2] + P0;
  const double* __restrict pp = m.p + P0, * __restrict Ko = m.K + o0, * __restrict uno = m.un + o0;
  const double* __restrict unmo = m.unm1 + o0, * __restrict So = m.S + o0, * __restrict KUo = m.KU + o0;
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) {
    const double a1 = 0.5 * (a0[i] + a0[i - oc]);
    const double a_n = 0.5 * (an[i] + an[i - oc]);
    const double a_nm1 = 0.5 * (anm[i] + anm[i - oc]);
    aP[i] = c0 * a1 * inv_dt + Ko[i] * inv_rho;
    double b_ = (c1 * a_n * uno[i] - c2 * a_nm1 * unmo[i]) * inv_dt;
    b_ += a1 * body - a1 * (pp[i] - pp[i - oc]) * (inv_rho * ihc);
    b_ += (So[i] + KUo[i]) * inv_rho;
    bb[i] = b_;
    a1v[i] = a1;
    ts[i] = 0.0;
    snb[i] = 0.0;
  }
}

/// The neighbour along d != c on side s whose face is a y wall: u_c = 0 on the wall half a cell
/// away (no-slip), or no stress (slip top); v = 0 there, so the transpose stress term vanishes.
template <int c>
[[gnu::always_inline]] inline void wall_neighbour(const MomentumArrays& m, const MomentumConstants& k,
                                                  const RowBuffers& r, int d, int s, std::int64_t P0) {
  if (s > 0 && k.top_slip) return;
  const std::int64_t oc = k.off[c];
  const double ih2d = k.ih2[d];
  double* __restrict aP = r.aP;
  const double* __restrict a1v = r.a1;
  const double* __restrict nP = m.nue + P0;
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) {
    const double nuf = 0.5 * (nP[i] + nP[i - oc]);
    aP[i] += 2.0 * a1v[i] * nuf * ih2d;
  }
}

/// QUICK's row constants for one neighbour: the upwind node is P (conv > 0) or N; its far node
/// is P - s e_d or N + s e_d. They say which of those nodes exist and which are wall zeros; reads
/// of a node that does not exist or is a wall zero (v at j = ny lies outside the ghosted box)
/// are redirected to P (offset 0) and their value is multiplied by zero.
struct QuickRow {
  double zP, zN, zUu, zUd;  // 0 for a wall zero, else 1
  double qup, qdn;          // 1 where the far node of an upwind P (N) exists
  std::int64_t oN, oUu, oUd;
};

template <int c, bool wall>
QuickRow quick_row(int j, int d, int s, std::int64_t od, int n1) {
  const int jN = j + s * kE[d][1];
  const bool okN = face_ok<c, wall>(jN, n1);
  const bool ok_up = face_ok<c, wall>(j - s * kE[d][1], n1) && face_ok<c, wall>(j, n1) && okN;
  const bool ok_dn = face_ok<c, wall>(j + 2 * s * kE[d][1], n1) && face_ok<c, wall>(j, n1) && okN;
  QuickRow q;
  q.zP = zero_node<c, wall>(j, n1) ? 0.0 : 1.0, q.zN = zero_node<c, wall>(jN, n1) ? 0.0 : 1.0;
  q.zUu = zero_node<c, wall>(j - s * kE[d][1], n1) ? 0.0 : 1.0;
  q.zUd = zero_node<c, wall>(j + 2 * s * kE[d][1], n1) ? 0.0 : 1.0;
  q.qup = ok_up ? 1.0 : 0.0, q.qdn = ok_dn ? 1.0 : 0.0;
  q.oN = okN && q.zN != 0.0 ? s * od : 0;
  q.oUu = ok_up && q.zUu != 0.0 ? -s * od : 0, q.oUd = ok_dn && q.zUd != 0.0 ? 2 * s * od : 0;
  return q;
}

/// One neighbour of the row's cells: its coefficients, the row's u_c, the side s and the
/// spacing along d, and QUICK's row constants.
struct NeighbourRow {
  double* ae;        // this neighbour's coefficients
  const double* uP;  // u_c at the row's cells
  double s, ihd, ih2d;
  // a weight, not a select on a known-zero neighbour: GCC 12 does not vectorise a select on a
  // loop-invariant bool, which left v's neighbour passes scalar (3x u's assembly time)
  double w_nb;
  QuickRow q;
};

/// Cell i's share of one neighbour, from the convecting face flux F (alpha_f u, m/s), the face
/// viscosity nuf (m^2/s) and the transpose-stress term tT (1/s): diffusion and implicit upwind
/// convection into a_P and a_nb, QUICK's deferred correction into the right-hand side.
template <bool use_quick>
[[gnu::always_inline]] inline void add_neighbour(const RowBuffers& r, const NeighbourRow& n, int i, double F,
                                                 double nuf, double tT) {
  r.ts[i] += n.s * tT * n.ihd;
  const double dcoef = r.a1[i] * nuf * n.ih2d;
  const double conv = F * n.ihd;
  r.aP[i] += dcoef + std::max(conv, 0.0);
  const double a = -dcoef + std::min(conv, 0.0);
  n.ae[i] = a;
  r.snb[i] += n.w_nb * std::abs(a);
  if constexpr (use_quick) {
    // rhs -= F (phi_QUICK - phi_upwind) / h, deferred correction
    const QuickRow& q = n.q;
    const double vP = q.zP * n.uP[i], vN = q.zN * n.uP[i + q.oN];
    const double vUu = q.zUu * n.uP[i + q.oUu], vUd = q.zUd * n.uP[i + q.oUd];
    const bool up = conv > 0.0;
    const double pc = up ? vP : vN, pd = up ? vN : vP, pu = up ? vUu : vUd;
    const double ok = up ? q.qup : q.qdn;
    const double quick = 0.75 * pc + 0.375 * pd - 0.125 * pu;
    r.b[i] -= ok * (conv * (quick - pc));
  }
}

/// The neighbour along c itself: its face is the cell centre Q = P (s > 0) or P - e_c.
template <int c, bool wall, bool use_quick>
[[gnu::always_inline]] inline void along_neighbour(const MomentumArrays& m, const MomentumConstants& k,
                                                   const RowBuffers& r, const NeighbourRow& n, int j, int s,
                                                   std::int64_t P0, std::int64_t fo) {
  const std::int64_t oc = k.off[c];
  const double sh = s * 0.5, ihc = k.ih[c];
  const double* __restrict F0 = m.F[c] + P0 + fo;
  const double* __restrict nQ = m.nue + P0 + fo;
  const double* __restrict uQ = m.u[c] + P0 + fo;
  const double zlo = zero_node<c, wall>(s > 0 ? j : j - kE[c][1], k.n1) ? 0.0 : 1.0;
  const double zhi = zero_node<c, wall>(s > 0 ? j + kE[c][1] : j, k.n1) ? 0.0 : 1.0;
  const std::int64_t ohi = zhi != 0.0 ? oc : 0;  // v at j = ny is outside the ghosted box
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) {
    const double F = sh * (F0[i] + F0[i + oc]);
    const double nuf = nQ[i];
    const double tT = nuf * (zhi * uQ[i + ohi] - zlo * uQ[i]) * ihc;
    add_neighbour<use_quick>(r, n, i, F, nuf, tT);
  }
}

/// A neighbour across d != c: its face is the d-face of cell E = P + e_d (s > 0) or P, and the
/// viscosity lives on the edge between four cells.
template <int c, bool use_quick>
[[gnu::always_inline]] inline void across_neighbour(const MomentumArrays& m, const MomentumConstants& k,
                                                    const RowBuffers& r, const NeighbourRow& n, int d, int s,
                                                    std::int64_t P0, std::int64_t fo) {
  const std::int64_t oc = k.off[c], od = k.off[d];
  const double sh = s * 0.5, ihc = k.ih[c];
  const double* __restrict FE = m.F[d] + P0 + fo;
  const double* __restrict nE = m.nue + P0 + fo;
  const double* __restrict uE = m.u[d] + P0 + fo;
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) {
    const double F = sh * (FE[i] + FE[i - oc]);
    const double nuf = 0.25 * (nE[i] + nE[i - oc] + nE[i - od] + nE[i - oc - od]);
    const double tT = nuf * (uE[i] - uE[i - oc]) * ihc;
    add_neighbour<use_quick>(r, n, i, F, nuf, tT);
  }
}

/// The neighbour along d on side s (entry e = 1 + 2 d + (s > 0) of the rows); sets bit e of
/// `present` unless it is a known zero.
template <int c, bool wall, bool use_quick>
[[gnu::always_inline]] inline void neighbour_terms(const MomentumArrays& m, const MomentumConstants& k,
                                                   const RowBuffers& r, int j, int d, int s, std::int64_t P0,
                                                   unsigned& present) {
  const std::int64_t od = k.off[d], oc = k.off[c];
  const int e = 1 + 2 * d + (s > 0);
  const int jN = j + s * kE[d][1];
  std::int64_t fo;             // first flux node (the second is fo - oc or fo + oc)
  bool nb_known_zero = false;  // neighbour is a wall value v = 0 (not an unknown)
  if (d != c) {
    const int jE = s > 0 ? jN : j;
    if (d == 1 && wall && (jE <= 0 || jE >= k.n1)) {
      wall_neighbour<c>(m, k, r, d, s, P0);
      return;
    }
    fo = s > 0 ? od : 0;
  } else {
    fo = s > 0 ? 0 : -oc;
    nb_known_zero = zero_node<c, wall>(jN, k.n1);
  }
  const NeighbourRow n{r.anb[e],
                       m.u[c] + P0,
                       static_cast<double>(s),
                       k.ih[d],
                       k.ih2[d],
                       nb_known_zero ? 0.0 : 1.0,
                       quick_row<c, wall>(j, d, s, od, k.n1)};
  if (!nb_known_zero) present |= 1u << e;
  if (d == c)
    along_neighbour<c, wall, use_quick>(m, k, r, n, j, s, P0, fo);
  else
    across_neighbour<c, use_quick>(m, k, r, n, d, s, P0, fo);
}

/// The row's end: transpose stress into the right-hand side, under-relaxation, the SIMPLEC
/// coefficient D and the inverse diagonal.
template <int c>
[[gnu::always_inline]] inline void finish_row(const MomentumArrays& m, const MomentumConstants& k,
                                              const RowBuffers& r, std::int64_t P0, std::int64_t o0) {
  const double inv_lam = k.inv_lam, rho = k.rho_kg_m3;
  double* __restrict aP = r.aP;
  const double* __restrict bb = r.b;
  const double* __restrict a1v = r.a1;
  const double* __restrict ts = r.ts;
  const double* __restrict snb = r.snb;
  const double* __restrict uP_ = m.u[c] + P0;
  double* __restrict rh = m.rhs + o0, * __restrict Dd = m.D + o0;
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) {
    const double b_ = bb[i] + a1v[i] * ts[i];
    const double aPr = aP[i] * inv_lam;
    rh[i] = b_ + (aPr - aP[i]) * uP_[i];
    aP[i] = aPr;
  }
  // SIMPLEC (Van Doormaal and Raithby 1984): u' = -(a/(rho (a_P - sum a_nb))) grad p'.
  // SIMPLE's a/(rho a_P) diverges for diffusion-dominated cells of high aspect ratio
  // (nu dt/h_y^2 >> 1 with h_x >> h_y, as on the paper's 1 mm grid with 6 cells across a
  // 6 mm gap).
  if (k.first_iteration)
#pragma GCC ivdep
    for (int i = 0; i < k.nx; ++i) Dd[i] = a1v[i] / (rho * (aP[i] - snb[i]));
  double* __restrict id = m.inv_diag + o0;
#pragma GCC ivdep
  for (int i = 0; i < k.nx; ++i) id[i] = 1.0 / aP[i];
}

/// The row buffers into the operator's arrays; entries of known zeros (wall values v = 0,
/// no-slip faces) are stored as 0.
inline void store_row(const MomentumArrays& m, const RowBuffers& r, std::int64_t o0, int nx,
                      unsigned present) {
  std::copy(r.aP, r.aP + nx, m.A[0] + o0);
  for (int e = 1; e < 7; ++e)
    if (present >> e & 1u)
      std::copy(r.anb[e], r.anb[e] + nx, m.A[e] + o0);
    else
      std::fill(m.A[e] + o0, m.A[e] + o0 + nx, 0.0);
}

template <int c>
MomentumConstants momentum_constants(const FluidSettings& s, double G_pa_m, double dt, double c0, double c1,
                                     double c2, bool first_iteration, const OwnedBox& b, const GhostBox& gb) {
  const auto& g = s.grid;
  MomentumConstants k;
  k.n1 = (int)g.n[1];
  k.nx = (int)b.size[0];
  k.off[0] = 1, k.off[1] = gb.size[0], k.off[2] = gb.size[0] * gb.size[1];
  const double h[3] = {g.dx(0), g.dx(1), g.dx(2)};
  for (int d = 0; d < 3; ++d) k.ih[d] = 1.0 / h[d], k.ih2[d] = k.ih[d] * k.ih[d];
  k.rho_kg_m3 = s.density_kg_m3;
  k.inv_rho = 1.0 / k.rho_kg_m3;
  k.c0 = c0, k.c1 = c1, k.c2 = c2;
  k.inv_dt = 1.0 / dt;
  const double lam = s.piso ? 1.0 : s.velocity_relaxation;  // PISO's sweeps need the unrelaxed equations
  k.inv_lam = 1.0 / lam;
  k.body_m_s2 = s.body_acceleration_m_s2[c] - (c == 2 ? G_pa_m / k.rho_kg_m3 : 0.0);
  k.top_slip = s.top_slip;
  k.first_iteration = first_iteration;
  return k;
}

}  // namespace

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
  BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.alpha[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.U[d], &u[d]));
    BC_PETSC(DMDAVecGetArray(layout_.da, ghosts_.F[d], &F[d]));
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
  BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.alpha[0], &al));
  for (int d = 0; d < 3; ++d) {
    BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.U[d], &u[d]));
    BC_PETSC(DMDAVecRestoreArray(layout_.da, ghosts_.F[d], &F[d]));
  }
}

void FluidSolver::compute_effective_viscosity() {
  BC_PETSC(VecCopy(ghosts_.nut, ghosts_.nue));
  BC_PETSC(VecShift(ghosts_.nue, s_.viscosity_pa_s / s_.density_kg_m3));
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
  const OwnedBox b = owned_box();
  const GhostBox gb = ghost_box();
  const MomentumConstants mc =
      momentum_constants<c>(s_, flow_.G_pa_m, dt, c0, c1, c2, first_iteration, b, gb);
  MomentumArrays m;
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(ghosts_.U[d], &m.u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecGetArrayRead(ghosts_.F[d], &m.F[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecGetArrayRead(ghosts_.alpha[l], &m.alpha[l]));
  BC_PETSC(VecGetArrayRead(ghosts_.P, &m.p));
  BC_PETSC(VecGetArrayRead(ghosts_.nue, &m.nue));
  BC_PETSC(VecGetArrayRead(flow_.Un[c], &m.un));
  BC_PETSC(VecGetArrayRead(flow_.Unm1[c], &m.unm1));
  BC_PETSC(VecGetArrayRead(coupling_.S[c], &m.S));
  BC_PETSC(VecGetArrayRead(coupling_.K[c], &m.K));
  BC_PETSC(VecGetArrayRead(coupling_.KU[c], &m.KU));
  BC_PETSC(VecGetArray(work_.rhs, &m.rhs));
  BC_PETSC(VecGetArray(work_.D[c], &m.D));
  BC_PETSC(VecGetArray(work_.inv_diag[c], &m.inv_diag));
  for (int e = 0; e < 7; ++e) m.A[e] = A.coef(e);
  const RowBuffers r(work_.row_buffers, mc.nx);

  std::int64_t o0 = 0;
  for (int k = (int)b.lo[2]; k < b.lo[2] + b.size[2]; ++k)
    for (int j = (int)b.lo[1]; j < b.lo[1] + b.size[1]; ++j, o0 += mc.nx) {
      const std::int64_t P0 = (k - gb.lo[2]) * mc.off[2] + (j - gb.lo[1]) * mc.off[1] + (b.lo[0] - gb.lo[0]);
      if (c == 1 && wall && j == 0) {
        identity_row(m, mc, o0);
        continue;
      }
      local_terms<c>(m, mc, r, P0, o0);
      unsigned present = 1u;  // bit e: entry e of these rows is written
      // unrolled, so that each neighbour's branches on d and s fold away as they did in one body
#pragma GCC unroll 3
      for (int d = 0; d < 3; ++d)
#pragma GCC unroll 2
        for (int s = -1; s <= 1; s += 2) neighbour_terms<c, wall, use_quick>(m, mc, r, j, d, s, P0, present);
      finish_row<c>(m, mc, r, P0, o0);
      store_row(m, r, o0, mc.nx, present);
    }

  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(ghosts_.U[d], &m.u[d]));
  for (int d = 0; d < 3; ++d) BC_PETSC(VecRestoreArrayRead(ghosts_.F[d], &m.F[d]));
  for (int l = 0; l < 3; ++l) BC_PETSC(VecRestoreArrayRead(ghosts_.alpha[l], &m.alpha[l]));
  BC_PETSC(VecRestoreArrayRead(ghosts_.P, &m.p));
  BC_PETSC(VecRestoreArrayRead(ghosts_.nue, &m.nue));
  BC_PETSC(VecRestoreArrayRead(flow_.Un[c], &m.un));
  BC_PETSC(VecRestoreArrayRead(flow_.Unm1[c], &m.unm1));
  BC_PETSC(VecRestoreArrayRead(coupling_.S[c], &m.S));
  BC_PETSC(VecRestoreArrayRead(coupling_.K[c], &m.K));
  BC_PETSC(VecRestoreArrayRead(coupling_.KU[c], &m.KU));
  BC_PETSC(VecRestoreArray(work_.rhs, &m.rhs));
  BC_PETSC(VecRestoreArray(work_.D[c], &m.D));
  BC_PETSC(VecRestoreArray(work_.inv_diag[c], &m.inv_diag));
}

}  // namespace boycott::fluid
