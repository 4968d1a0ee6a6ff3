#include "particles/slab_decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace boycott::particles {

SlabDecomposition SlabDecomposition::serial(double z_lo, double z_hi) {
  SlabDecomposition d;
  d.z_bounds = {z_lo, z_hi};
  return d;
}

SlabDecomposition SlabDecomposition::gather(MPI_Comm comm, double z_lo, double z_hi) {
  SlabDecomposition d;
  d.comm = comm;
  MPI_Comm_rank(comm, &d.rank);
  MPI_Comm_size(comm, &d.size);
  const double mine[2] = {z_lo, z_hi};
  std::vector<double> all(2 * static_cast<std::size_t>(d.size));
  MPI_Allgather(mine, 2, MPI_DOUBLE, all.data(), 2, MPI_DOUBLE, comm);
  d.z_bounds.resize(static_cast<std::size_t>(d.size) + 1);
  for (int r = 0; r < d.size; ++r) {
    d.z_bounds[r] = all[2 * r];
    if (r > 0 && all[2 * r] != all[2 * r - 1])
      throw std::logic_error("SlabDecomposition: the ranks' slabs do not tile the box in rank order");
  }
  d.z_bounds.back() = all.back();
  return d;
}

int SlabDecomposition::owner(double z) const {
  const double lo = z_bounds.front(), len = box_length();
  z -= len * std::floor((z - lo) / len);
  // upper_bound: the first boundary above z; the slab below it owns z.
  const auto it = std::upper_bound(z_bounds.begin() + 1, z_bounds.end() - 1, z);
  return static_cast<int>(it - (z_bounds.begin() + 1));
}

double SlabDecomposition::distance_to_slab(double z, int r) const {
  const double a = z_bounds[r], b = z_bounds[r + 1], len = box_length();
  double best = len;
  for (int m = -1; m <= 1; ++m) {
    const double zz = z + m * len;
    const double d = zz < a ? a - zz : (zz >= b ? zz - b : 0.0);
    best = std::min(best, d);
  }
  return best;
}

double ordered_sum(MPI_Comm comm, double local) {
  return ordered_sum(comm, std::vector<double>{local})[0];
}

std::vector<double> ordered_sum(MPI_Comm comm, const std::vector<double>& local) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size == 1) return local;
  const int n = static_cast<int>(local.size());
  std::vector<double> all(static_cast<std::size_t>(n) * size);
  MPI_Allgather(local.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, comm);
  std::vector<double> sum(local.size(), 0.0);
  for (int r = 0; r < size; ++r)
    for (int k = 0; k < n; ++k) sum[k] += all[static_cast<std::size_t>(r) * n + k];
  return sum;
}

double global_max(MPI_Comm comm, double local) {
  double g = local;
  MPI_Allreduce(&local, &g, 1, MPI_DOUBLE, MPI_MAX, comm);
  return g;
}

double global_min(MPI_Comm comm, double local) {
  double g = local;
  MPI_Allreduce(&local, &g, 1, MPI_DOUBLE, MPI_MIN, comm);
  return g;
}

std::int64_t global_sum(MPI_Comm comm, std::int64_t local) {
  std::int64_t g = local;
  MPI_Allreduce(&local, &g, 1, MPI_INT64_T, MPI_SUM, comm);
  return g;
}

}  // namespace boycott::particles
