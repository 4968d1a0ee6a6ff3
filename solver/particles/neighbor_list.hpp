#pragma once
// O(N) linked-cell neighbour search producing a half Verlet list (each pair once, j > i) in CSR
// form. Pairs are kept when their centre distance (minimum image in periodic directions) is
// below cutoff = 2 r_max + skin; the list stays valid until some particle has moved skin/2.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "particles/particle_store.hpp"

namespace boycott::particles {

struct BoxGeometry {
  std::array<double, 3> lo = {0.0, 0.0, 0.0};   ///< m
  std::array<double, 3> len = {1.0, 1.0, 1.0};  ///< m
  std::array<bool, 3> periodic = {true, false, true};
  /// Period of direction d for min_image (m): its length, or 0 where it is not periodic.
  double period(int d) const { return periodic[d] ? len[d] : 0.0; }
  double inv_len(int d) const { return 1.0 / len[d]; }
};

class NeighborList {
 public:
  /// Bins particles [0, n) into cells of at least `cutoff` and builds the half list. With
  /// rows < n, only particles [0, rows) get pairs (ghost copies after them are partners only).
  void build(const ParticleStore& s, const BoxGeometry& g, double cutoff_m, std::size_t rows = kAllRows);
  /// Bins particles and returns the storage order that groups them cell by cell (x fastest), for
  /// cache locality. After the caller permutes the particles by it, build_binned() builds the
  /// list without binning again.
  std::vector<std::size_t> bin_and_order(const ParticleStore& s, const BoxGeometry& g, double cutoff_m);
  void build_binned(const ParticleStore& s, const BoxGeometry& g, double cutoff_m,
                    std::size_t rows = kAllRows);
  static constexpr std::size_t kAllRows = static_cast<std::size_t>(-1);

  std::size_t pair_count() const { return neighbors.size(); }

  std::vector<std::uint32_t> offsets;    ///< size n + 1; pairs of i are [offsets[i], offsets[i+1])
  std::vector<std::uint32_t> neighbors;  ///< j of each pair, j > i

 private:
  void bin(const ParticleStore& s, const BoxGeometry& g, double cutoff_m);
  /// Whether the rows [0, rows) are stored cell by cell; if so, counts them per cell.
  bool rows_stored_by_cell(std::size_t rows);
  std::array<int, 3> nc_{};
  std::vector<int> cell_of_;
  std::vector<std::uint32_t> cell_start_, cell_items_;
  std::vector<std::uint32_t> rows_in_cell_;  ///< per cell, its items that are rows (build_binned)
};

}  // namespace boycott::particles
