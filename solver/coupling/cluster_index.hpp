#pragma once
// The clustering of the particles in the x-z plane, as the paper's images see them (Figs. 7, 13:
// the particles looked at along y, uniform at small angles, in plumes and spikes at moderate
// ones): the dispersion index (stats/dispersion.hpp) of the particle counts in the columns of
// the fluid grid, one per x-z cell, summed over the gap's y cells. 1 for particles placed at
// random, below 1 for a more even (lattice-like) arrangement, above 1 for clusters.
//
// Why particle centres counted per column, not the deposited solid fraction: the particles are of
// one size, so a column's solid fraction is its count times V_p over the column's volume and the
// index of the fractions is that of the counts; and the deposition kernel spreads each particle
// over neighbouring cells, which smooths the field and lowers the index of a random arrangement
// below 1 by an amount that depends on the kernel. Counted centres keep the reference exact.
// Why the fluid grid's x-z cells: they are the scale the unresolved coupling resolves (1 mm at
// full size, 1.7 particle diameters); clusters smaller than a column are not seen, those larger
// raise the index by about the particles each holds in a column.
#include <array>
#include <cstdint>
#include <vector>

#include "core/grid_spec.hpp"

namespace boycott::particles {
struct ParticleStore;
}

namespace boycott::coupling {

class CoupledSystem;

/// The local particles' centres counted per x-z column of grid g (x fastest, nx nz columns), the
/// box starting at lo (m); positions outside the box in x or z (periodic) are wrapped into it,
/// positions in y are not looked at.
std::vector<std::int64_t> xz_column_counts(const particles::ParticleStore& s, const GridSpec& g,
                                           const std::array<double, 3>& lo_m);

/// The run's cluster index now: the columns' counts summed over the ranks (integers, so the sum
/// is exact whatever the order). Collective.
double xz_cluster_index(const CoupledSystem& run);

}  // namespace boycott::coupling
