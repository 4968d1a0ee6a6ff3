#pragma once
// Writes the values of a 7-point star matrix made by DMCreateMatrix on a DMDA straight into its
// AIJ value arrays. The fluid applies its operators matrix-free (stencil_operator.hpp) and uses
// this only for the AIJ copies that a user-chosen preconditioner or the AMG fallback needs.
// MatSetValuesStencil costs ~350 ns per row (stencil to local to global index mapping, then a column search
// per entry), which made it ~70 % of the momentum assembly on the 200 x 6 x 100 bench mesh; the nonzero
// pattern of these matrices never changes, so the position of each row's seven entries is looked up once,
// here, and reused for every assembly.
//
// Entry e of a row: 0 the diagonal, 1 + 2 d + (s > 0) the neighbour at -e_d (s < 0) or +e_d.
// Rows are the rank's owned cells in PETSc order (x fastest over the owned box). Entries of a
// neighbour outside a non-periodic boundary do not exist and must not be written.
#include <petscdmda.h>

#include <cstdint>
#include <vector>

namespace boycott::fluid {

class StencilMatrixWriter {
 public:
  /// Looks up the slots of every owned row of M (created by DMCreateMatrix(da), star stencil of
  /// width 1, assembled once). Any other matrix from the same DM has the same slots.
  StencilMatrixWriter(DM da, Mat M);

  /// Gets M's value arrays and zeroes them.
  void begin(Mat M);
  /// Adds v to entry e of owned row o (between begin and end).
  void add(std::int64_t o, int e, double v) {
    const std::int64_t s = slots_[7 * o + e];
    if (s >= 0)
      diag_[s] += v;
    else
      offd_[-s - 1] += v;
  }
  /// Entry e of owned row o exists in the pattern (not beyond a non-periodic boundary).
  bool has(std::int64_t o, int e) const { return slots_[7 * o + e] != kMissing; }
  /// Restores the arrays and assembles M (nothing moves between ranks: all rows are owned).
  void end(Mat M);

 private:
  static constexpr std::int64_t kMissing = INT64_MIN;
  std::vector<std::int64_t> slots_;  // >= 0: index into the diagonal block's values; < 0: off-diagonal block
  PetscInt nnz_diag_ = 0, nnz_offd_ = 0;  // stored values of the two blocks
  Mat Ad_ = nullptr, Ao_ = nullptr;       // blocks of the matrix between begin and end
  PetscScalar* diag_ = nullptr;
  PetscScalar* offd_ = nullptr;
};

}  // namespace boycott::fluid
