#pragma once
// Field snapshots for ParaView: one HDF5 file per time, DIR/snapshots/snap_<index>.h5, and one
// XDMF index, DIR/snapshots/fields.xmf, listing every snapshot of the run as a temporal collection
// (each time a spatial collection of the particles, a polyvertex point set, and the fluid, a
// co-rectilinear grid with cell data). Open fields.xmf in ParaView ("Xdmf3 Reader").
//
// Layout of snap_<index>.h5 (N particles in id order, grid of nx * ny * nz cells):
//   time                        double [1]          simulated time, s
//   particles/id                int64  [N]          ascending
//   particles/position          double [N][3]       m, wrapped into the box along periodic axes
//   particles/velocity          double [N][3]       m/s
//   particles/angular_velocity  double [N][3]       rad/s
//   particles/radius            double [N]          m
//   fluid/<name>                double [nz][ny][nx] cell-centred (alpha_f, pressure, u, v, w)
//   fluid_fields                string [F]          the names of the fluid datasets (none: no fluid)
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/grid_spec.hpp"

namespace boycott::io {

struct SnapshotData {
  double time_s = 0.0;
  // particles, in any order (the writer sorts them by id); all arrays of the same length
  std::vector<std::int64_t> id;
  std::vector<double> x, y, z, vx, vy, vz, wx, wy, wz, radius;
  // fluid, cell-centred, x fastest (nx * ny * nz values each); empty when the scene has no fluid
  std::vector<std::pair<std::string, std::vector<double>>> cell_fields;
};

/// `x` wrapped into [0, length): where a periodic box draws or stores a particle.
double wrap_into_box(double x, double length);

/// Writes DIR/snapshots/snap_<index>.h5 and rewrites DIR/snapshots/fields.xmf over all snapshot
/// files present. Returns the HDF5 file written. std::logic_error when the particle arrays differ
/// in length.
std::filesystem::path write_snapshot(const std::filesystem::path& run_dir, int index, const SnapshotData& d,
                                     const GridSpec& grid);

}  // namespace boycott::io
