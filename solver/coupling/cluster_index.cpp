#include "coupling/cluster_index.hpp"

#include <cmath>

#include <mpi.h>

#include "coupling/coupled_system.hpp"
#include "particles/particle_store.hpp"
#include "stats/dispersion.hpp"

namespace boycott::coupling {

namespace {

/// The column index of coordinate x (m from the box's lower edge) along a periodic direction of
/// n cells of size h, wrapped into [0, n).
std::int64_t wrapped_cell(double x, double h, std::int64_t n) {
  std::int64_t i = static_cast<std::int64_t>(std::floor(x / h)) % n;
  if (i < 0) i += n;
  return i;
}

}  // namespace

std::vector<std::int64_t> xz_column_counts(const particles::ParticleStore& s, const GridSpec& g,
                                           const std::array<double, 3>& lo_m) {
  const std::int64_t nx = g.n[0], nz = g.n[2];
  const double hx = g.dx(0), hz = g.dx(2);
  std::vector<std::int64_t> counts(static_cast<std::size_t>(nx * nz), 0);
  for (std::size_t i = 0; i < s.n_local; ++i) {
    const std::int64_t cx = wrapped_cell(s.x[i] - lo_m[0], hx, nx);
    const std::int64_t cz = wrapped_cell(s.z[i] - lo_m[2], hz, nz);
    ++counts[static_cast<std::size_t>(cx + nx * cz)];
  }
  return counts;
}

double xz_cluster_index(const CoupledSystem& run) {
  std::vector<std::int64_t> counts =
      xz_column_counts(run.dem().particles(), GridSpec::from_case(run.params()), run.dem().config().box.lo);
  // Before the particles are shared out every rank holds all of them (as in global_sum).
  if (run.dem().decomposition().parallel())
    MPI_Allreduce(MPI_IN_PLACE, counts.data(), static_cast<int>(counts.size()), MPI_INT64_T, MPI_SUM,
                  run.fluid().comm());
  return stats::dispersion_index(counts);
}

}  // namespace boycott::coupling
