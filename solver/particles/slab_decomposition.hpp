#pragma once
// How particles are shared among MPI ranks: rank r owns the particles whose centre lies in the
// z-slab [z_bounds[r], z_bounds[r+1]) of the box (the fluid grid's z-slabs, so that a particle and
// the cells it exchanges with live on the same rank). The box is periodic in z.
#include <mpi.h>

#include <cstdint>
#include <vector>

namespace boycott::particles {

struct SlabDecomposition {
  MPI_Comm comm = MPI_COMM_SELF;
  int rank = 0, size = 1;
  /// size + 1 boundaries, m, increasing; front() and back() are the box's ends in z.
  std::vector<double> z_bounds;

  /// One rank owning the whole box [z_lo, z_hi).
  static SlabDecomposition serial(double z_lo, double z_hi);
  /// The slabs of `comm`'s ranks; every rank passes its own [z_lo, z_hi) (m), in rank order.
  static SlabDecomposition gather(MPI_Comm comm, double z_lo, double z_hi);

  bool parallel() const { return size > 1; }
  double box_length() const { return z_bounds.back() - z_bounds.front(); }
  /// The rank owning a centre at z (wrapped into the box first).
  int owner(double z) const;
  /// Distance (m) from z to rank r's slab along z, through the periodic images.
  double distance_to_slab(double z, int r) const;
};

/// Sum of one value per rank, added in rank order on every rank: the same bits on every rank
/// and in every run on the same number of ranks (MPI_Allreduce need not promise either).
double ordered_sum(MPI_Comm comm, double local);
/// The same for several values at once (element-wise).
std::vector<double> ordered_sum(MPI_Comm comm, const std::vector<double>& local);
double global_max(MPI_Comm comm, double local);
double global_min(MPI_Comm comm, double local);
std::int64_t global_sum(MPI_Comm comm, std::int64_t local);

}  // namespace boycott::particles
