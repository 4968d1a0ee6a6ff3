#pragma once
// Fills a DMDA's ghosted local vector from its global vector: the same values as
// DMGlobalToLocal(INSERT_VALUES), faster where each rank owns whole z-planes (one rank, or the
// fluid's FFTW slabs). PETSc's scatter copies every owned value through an index list, one value
// at a time (~105 us per call for 60 000 values on each of 2 ranks, ~180 us on one rank for
// 120 000), and a fluid step makes 60-140 such calls. Here the owned rows are block copies, the
// periodic x (and y) ghosts are filled from the rank's own rows, and only the z ghost planes travel
// between ranks, straight from and into the local arrays. Any other decomposition (x or y split,
// non-periodic x or z) falls back to DMGlobalToLocal.
#include <petscdmda.h>

#include <cstddef>

namespace boycott::fluid {

class HaloExchange {
 public:
  /// `dm` is not owned and must outlive this.
  explicit HaloExchange(DM dm);
  ~HaloExchange();
  HaloExchange(const HaloExchange&) = delete;
  HaloExchange& operator=(const HaloExchange&) = delete;
  /// local = global with ghosts (DMGlobalToLocal with INSERT_VALUES).
  void fill(Vec global, Vec local) const;
  /// Whether the block-copy path is used (else DMGlobalToLocal).
  bool fast() const { return fast_; }
  /// Fast path only: the plane below this slab's first owned plane and the plane above its last
  /// (z periodic; nx x ny values each, x fastest), from the owned values `global` (x fastest,
  /// then y, then z). An operator that reads one plane beyond its slab needs these alone, not
  /// a ghosted copy of the whole vector.
  void boundary_planes(const double* global, double* below, double* above) const;

 private:
  /// The rank below gets `count` values from first_owned (its upper ghosts), the rank above from
  /// last_owned; lower and upper receive theirs (periodic z; on one rank, this slab's own).
  /// Tags tag and tag + 1.
  void exchange_planes(const double* first_owned, const double* last_owned, double* lower, double* upper,
                       std::size_t count, int tag) const;

  DM dm_;
  MPI_Comm comm_ = MPI_COMM_NULL;  // a duplicate of the DM's: these messages meet no others
  bool fast_ = false;
  PetscInt w_ = 0;   // stencil width: ghost planes in z, ghost cells in x
  PetscInt wy_ = 0;  // ghost rows in y (w where y is periodic, else 0)
  PetscInt nx_ = 0, ny_ = 0, zm_ = 0, gxm_ = 0, gym_ = 0;
  int below_ = -1, above_ = -1;  // ranks owning the planes below and above this slab (periodic)
};

}  // namespace boycott::fluid
