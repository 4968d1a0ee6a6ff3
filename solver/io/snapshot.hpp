#pragma once
// Field snapshots for ParaView: one HDF5 file per time (particles and cell-centred fluid fields)
// and an XDMF index, DIR/snapshots/fields.xmf, listing every snapshot of the run as a temporal
// collection (particles as a polyvertex cloud, the fluid as a co-rectilinear grid with cell data).
#include <filesystem>
#include <string>
#include <vector>

#include "core/grid_spec.hpp"

namespace boycott::io {

struct SnapshotData {
  double time_s = 0.0;
  // particles
  std::vector<double> x, y, z, vx, vy, vz, radius;
  // fluid, cell-centred, x fastest (nx * ny * nz values each); empty when the scene has no fluid
  std::vector<std::pair<std::string, std::vector<double>>> cell_fields;
};

/// Writes DIR/snapshots/snap_<index>.h5 and rewrites DIR/snapshots/fields.xmf over all snapshot
/// files present. Returns the HDF5 file written.
std::filesystem::path write_snapshot(const std::filesystem::path& run_dir, int index, const SnapshotData& d,
                                     const GridSpec& grid);

}  // namespace boycott::io
