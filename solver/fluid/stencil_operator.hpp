#pragma once
// A 7-point star operator on a DMDA, stored as seven coefficient arrays and applied without an
// assembled matrix (a PETSc MATSHELL). The momentum and pressure-correction systems are this
// shape; their Krylov solves need only products, and the default preconditioners (point Jacobi
// from the diagonal, the spectral Poisson shell) no matrix entries. Against an AIJ matrix an
// application reads no column indices (~1/3 of AIJ's traffic on this stencil) and the assembly
// stores whole rows of coefficients instead of scattering each value to its slot; a
// preconditioner that does need the entries gets an AIJ copy (copy_to).
//
// Entry e of a row: 0 the diagonal, 1 + 2 d + (s > 0) the neighbour at -e_d (s < 0) or +e_d.
// Rows are the rank's owned cells in PETSc order (x fastest over the owned box). Where y is not
// periodic the -y entry of the first y row and the +y entry of the last do not exist: they are
// never read. Entries of neighbours the caller knows to be zero must be stored as 0.
#include <petscdmda.h>

#include <array>
#include <cstdint>
#include <vector>

#include "fluid/halo_exchange.hpp"

namespace boycott::fluid {

class StencilMatrixWriter;

class StencilOperator {
 public:
  /// `dm`: a DMDA with a star or box stencil of width >= 1 (not owned; must outlive this).
  explicit StencilOperator(DM dm);
  ~StencilOperator();
  StencilOperator(const StencilOperator&) = delete;
  StencilOperator& operator=(const StencilOperator&) = delete;

  /// Coefficients of entry e, one per owned row.
  double* coef(int e) { return coef_[e].data(); }
  const double* coef(int e) const { return coef_[e].data(); }
  /// The operator as a MATSHELL (MatMult, MatGetDiagonal), owned by this object.
  Mat mat() const { return shell_; }
  /// y = A x (global vectors of the DM).
  void apply(Vec x, Vec y) const;
  /// y = diag(w) A x, each row's sum multiplied by w: a product and a point-Jacobi application
  /// (w the reciprocal diagonal) in one pass, the same values as the two in sequence.
  void apply_scaled(Vec x, Vec y, Vec w) const;
  /// The operator behind `A` when A is one of these operators' MATSHELLs, else nullptr.
  static const StencilOperator* of(Mat A);
  /// The same product through a ghosted copy of x (any decomposition; apply() uses it where the
  /// ranks do not own whole z-planes). Public so that tests can hold the two paths to the bit.
  void apply_ghosted(Vec x, Vec y) const;
  /// Writes the coefficients into M (an AIJ matrix of the DM, whose slots W has looked up).
  void copy_to(Mat M, StencilMatrixWriter& W) const;

 private:
  void product(Vec x, Vec y, Vec w) const;  // apply (w null) or apply_scaled

  DM dm_;
  HaloExchange halo_;
  Vec xl_ = nullptr;                    // ghosted work vector (apply_ghosted)
  mutable std::vector<double> planes_;  // the planes below and above the slab (apply)
  Mat shell_ = nullptr;
  std::array<std::vector<double>, 7> coef_;
  std::array<PetscInt, 3> lo_{}, size_{}, glo_{}, gsize_{};
  PetscInt ny_ = 0;
  bool wall_y_ = false;
};

}  // namespace boycott::fluid
