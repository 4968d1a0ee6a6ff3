#include "fluid/stencil_matrix.hpp"

#include "fluid/petsc_check.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace boycott::fluid {

namespace {

constexpr auto check = petsc_check;

/// Diagonal and off-diagonal blocks (the off-diagonal one null on one rank, with its map from
/// compressed to global columns).
void blocks(Mat M, Mat* Ad, Mat* Ao, const PetscInt** garray) {
  PetscBool mpi = PETSC_FALSE;
  check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(M), MATMPIAIJ, &mpi), "PetscObjectTypeCompare");
  if (mpi) {
    check(MatMPIAIJGetSeqAIJ(M, Ad, Ao, garray), "MatMPIAIJGetSeqAIJ");
  } else {
    PetscBool seq = PETSC_FALSE;
    check(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(M), MATSEQAIJ, &seq),
          "PetscObjectTypeCompare");
    if (!seq) throw std::runtime_error("StencilMatrixWriter: the matrix is neither seqaij nor mpiaij");
    *Ad = M, *Ao = nullptr, *garray = nullptr;
  }
}

}  // namespace

StencilMatrixWriter::StencilMatrixWriter(DM da, Mat M) {
  Mat Ad, Ao;
  const PetscInt* garray;
  blocks(M, &Ad, &Ao, &garray);
  PetscInt nrows, nro;
  const PetscInt *ia, *ja, *ib = nullptr, *jb = nullptr;
  PetscBool done;
  check(MatGetRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done), "MatGetRowIJ");
  if (!done) throw std::runtime_error("StencilMatrixWriter: no row structure");
  if (Ao) {
    check(MatGetRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &nro, &ib, &jb, &done), "MatGetRowIJ");
    if (!done) throw std::runtime_error("StencilMatrixWriter: no row structure");
  }
  nnz_diag_ = ia[nrows];
  nnz_offd_ = Ao ? ib[nro] : 0;
  PetscInt rstart, rend;
  check(MatGetOwnershipRange(M, &rstart, &rend), "MatGetOwnershipRange");

  PetscInt xs, ys, zs, xm, ym, zm, gxs, gys, gzs, gxm, gym, gzm, mx, my, mz;
  DMBoundaryType bx, by, bz;
  check(DMDAGetCorners(da, &xs, &ys, &zs, &xm, &ym, &zm), "DMDAGetCorners");
  check(DMDAGetGhostCorners(da, &gxs, &gys, &gzs, &gxm, &gym, &gzm), "DMDAGetGhostCorners");
  check(DMDAGetInfo(da, nullptr, &mx, &my, &mz, nullptr, nullptr, nullptr, nullptr, nullptr, &bx, &by, &bz,
                    nullptr),
        "DMDAGetInfo");
  ISLocalToGlobalMapping ltog;
  check(DMGetLocalToGlobalMapping(da, &ltog), "DMGetLocalToGlobalMapping");
  const PetscInt* l2g;
  check(ISLocalToGlobalMappingGetIndices(ltog, &l2g), "ISLocalToGlobalMappingGetIndices");

  const PetscInt n[3] = {mx, my, mz};
  const bool periodic[3] = {bx == DM_BOUNDARY_PERIODIC, by == DM_BOUNDARY_PERIODIC,
                            bz == DM_BOUNDARY_PERIODIC};
  slots_.assign(7 * static_cast<std::size_t>(xm) * ym * zm, kMissing);
  std::int64_t o = 0;
  for (PetscInt k = zs; k < zs + zm; ++k)
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i, ++o) {
        if (o >= nrows) throw std::runtime_error("StencilMatrixWriter: more cells than matrix rows");
        for (int e = 0; e < 7; ++e) {
          PetscInt q[3] = {i, j, k};
          if (e > 0) q[(e - 1) / 2] += (e % 2 == 0) ? 1 : -1;
          bool inside = true;
          for (int d = 0; d < 3; ++d) inside = inside && (periodic[d] || (q[d] >= 0 && q[d] < n[d]));
          if (!inside) continue;
          const PetscInt local = ((q[2] - gzs) * gym + (q[1] - gys)) * gxm + (q[0] - gxs);
          const PetscInt col = l2g[local];
          std::int64_t slot = kMissing;
          if (col >= rstart && col < rend) {
            for (PetscInt p = ia[o]; p < ia[o + 1]; ++p)
              if (ja[p] == col - rstart) slot = p;
          } else if (Ao) {
            for (PetscInt p = ib[o]; p < ib[o + 1]; ++p)
              if (garray[jb[p]] == col) slot = -(p + 1);
          }
          if (slot == kMissing)
            throw std::runtime_error("StencilMatrixWriter: stencil entry not in the matrix pattern");
          slots_[7 * o + e] = slot;
        }
      }
  check(ISLocalToGlobalMappingRestoreIndices(ltog, &l2g), "ISLocalToGlobalMappingRestoreIndices");
  check(MatRestoreRowIJ(Ad, 0, PETSC_FALSE, PETSC_FALSE, &nrows, &ia, &ja, &done), "MatRestoreRowIJ");
  if (Ao) check(MatRestoreRowIJ(Ao, 0, PETSC_FALSE, PETSC_FALSE, &nro, &ib, &jb, &done), "MatRestoreRowIJ");
}

void StencilMatrixWriter::begin(Mat M) {
  const PetscInt* garray;
  blocks(M, &Ad_, &Ao_, &garray);
  auto open = [](Mat B, PetscScalar** v, PetscInt nz) {
    check(MatSeqAIJGetArray(B, v), "MatSeqAIJGetArray");
    std::fill(*v, *v + nz, 0.0);
  };
  open(Ad_, &diag_, nnz_diag_);
  if (Ao_) open(Ao_, &offd_, nnz_offd_);
}

void StencilMatrixWriter::end(Mat M) {
  check(MatSeqAIJRestoreArray(Ad_, &diag_), "MatSeqAIJRestoreArray");
  if (Ao_) check(MatSeqAIJRestoreArray(Ao_, &offd_), "MatSeqAIJRestoreArray");
  Ad_ = Ao_ = nullptr;
  check(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}

}  // namespace boycott::fluid
