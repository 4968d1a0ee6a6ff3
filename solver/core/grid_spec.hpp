#pragma once
// Geometry of the uniform Cartesian fluid grid, shared by the fluid solver (which lays it out
// with PETSc) and the coupling (which deposits onto and interpolates from it) without either
// seeing the other's data structures.
#include <array>
#include <cstdint>

#include "core/case_params.hpp"

namespace boycott {

struct GridSpec {
  std::array<std::int64_t, 3> n = {1, 1, 1};         ///< cells in x, y, z
  std::array<double, 3> length_m = {1.0, 1.0, 1.0};  ///< domain extent from the origin
  std::array<bool, 3> periodic = {true, false, true};

  double dx(int d) const { return length_m[d] / static_cast<double>(n[d]); }
  double cell_volume_m3() const { return dx(0) * dx(1) * dx(2); }
  std::int64_t cell_count() const { return n[0] * n[1] * n[2]; }
  /// Linear index of cell (i, j, k), x fastest.
  std::int64_t cell_index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i + n[0] * (j + n[1] * k);
  }

  static GridSpec from_case(const CaseParams& p) {
    GridSpec g;
    g.n = p.domain.cells;
    g.length_m = {p.domain.length_x_m, p.domain.width_y_m, p.domain.height_z_m};
    g.periodic = {true, p.domain.periodic_y, true};
    return g;
  }
};

}  // namespace boycott
