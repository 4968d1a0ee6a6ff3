#include "particles/neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "particles/min_image.hpp"

namespace boycott::particles {

namespace {
int cell_coord(double p, double lo, double len, int n, bool periodic) {
  double f = (p - lo) / len;
  if (periodic) f -= std::floor(f);
  int c = static_cast<int>(f * n);
  return std::clamp(c, 0, n - 1);
}

/// Which cells neighbour a cell, per direction: the offsets (deduplicated where a periodic
/// direction has fewer than 3 cells) and each coordinate's neighbour at wrap[d][k + 1 + o] (-1
/// outside a wall), so that no integer division is made per particle and cell.
struct CellNeighbourhood {
  std::array<std::vector<int>, 3> offs, wrap;
};

CellNeighbourhood cell_neighbourhood(const std::array<int, 3>& nc, const BoxGeometry& g) {
  CellNeighbourhood nh;
  for (int d = 0; d < 3; ++d) {
    if (nc[d] == 1)
      nh.offs[d] = {0};
    else if (nc[d] == 2)
      nh.offs[d] = g.periodic[d] ? std::vector<int>{0, 1} : std::vector<int>{-1, 0, 1};
    else
      nh.offs[d] = {-1, 0, 1};
    nh.wrap[d].resize(static_cast<std::size_t>(nc[d]) + 2);
    for (int k = -1; k <= nc[d]; ++k)
      nh.wrap[d][static_cast<std::size_t>(k + 1)] =
          g.periodic[d] ? (k + nc[d]) % nc[d] : (k < 0 || k >= nc[d] ? -1 : k);
  }
  return nh;
}

/// The neighbour cells of cell c in the scan order (z, y, x offsets) into nb; returns their number.
int neighbour_cells(int c, const std::array<int, 3>& nc, const CellNeighbourhood& nh, int (&nb)[27]) {
  int n_nb = 0;
  const int cx = c % nc[0], cy = (c / nc[0]) % nc[1], cz = c / (nc[0] * nc[1]);
  for (int oz : nh.offs[2]) {
    const int kz = nh.wrap[2][static_cast<std::size_t>(cz + 1 + oz)];
    if (kz < 0) continue;
    for (int oy : nh.offs[1]) {
      const int ky = nh.wrap[1][static_cast<std::size_t>(cy + 1 + oy)];
      if (ky < 0) continue;
      for (int ox : nh.offs[0]) {
        const int kx = nh.wrap[0][static_cast<std::size_t>(cx + 1 + ox)];
        if (kx < 0) continue;
        nb[n_nb++] = kx + nc[0] * (ky + nc[1] * kz);
      }
    }
  }
  return n_nb;
}

}  // namespace

void NeighborList::bin(const ParticleStore& s, const BoxGeometry& g, double cutoff) {
  for (int d = 0; d < 3; ++d) {
    if (g.periodic[d] && g.len[d] < 2.0 * cutoff)
      throw std::invalid_argument(
          fmt::format("periodic length {} m in direction {} is below twice the neighbour cutoff {} m",
                      g.len[d], d, cutoff));
    nc_[d] = std::max(1, static_cast<int>(std::floor(g.len[d] / cutoff)));
  }
  const std::size_t n = s.size();
  const std::size_t ncell = static_cast<std::size_t>(nc_[0]) * nc_[1] * nc_[2];
  cell_of_.resize(n);
  cell_start_.assign(ncell + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int cx = cell_coord(s.x[i], g.lo[0], g.len[0], nc_[0], g.periodic[0]);
    const int cy = cell_coord(s.y[i], g.lo[1], g.len[1], nc_[1], g.periodic[1]);
    const int cz = cell_coord(s.z[i], g.lo[2], g.len[2], nc_[2], g.periodic[2]);
    cell_of_[i] = cx + nc_[0] * (cy + nc_[1] * cz);
    ++cell_start_[cell_of_[i] + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) cell_items_[fill[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
}

std::vector<std::size_t> NeighborList::bin_and_order(const ParticleStore& s, const BoxGeometry& g,
                                                     double cutoff) {
  bin(s, g, cutoff);
  std::vector<std::size_t> order(cell_items_.begin(), cell_items_.end());
  // The bins as they will be once the particles are stored in this order.
  std::vector<int> cell_sorted(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    cell_sorted[k] = cell_of_[order[k]];
    cell_items_[k] = static_cast<std::uint32_t>(k);
  }
  cell_of_.swap(cell_sorted);
  return order;
}

void NeighborList::build(const ParticleStore& s, const BoxGeometry& g, double cutoff, std::size_t rows) {
  bin(s, g, cutoff);
  build_binned(s, g, cutoff, rows);
}

bool NeighborList::rows_stored_by_cell(std::size_t rows) {
  // With the rows [0, rows) stored cell by cell (bin_and_order; a restart at the reference
  // positions), each cell's items are its rows, a contiguous increasing index range, then its
  // ghost copies (indices >= rows, appended after the rows; the binning keeps index order within
  // a cell). The half list (j > i) then needs only the ghosts of a lower cell and what follows i
  // in its own cell, which halves the distance tests. The pairs kept and their order are those
  // of the full scan.
  bool by_cell = true;
  for (std::size_t i = 1; i < rows && by_cell; ++i) by_cell = cell_of_[i - 1] <= cell_of_[i];
  if (by_cell) {
    rows_in_cell_.assign(cell_start_.size() - 1, 0);
    for (std::size_t i = 0; i < rows; ++i) ++rows_in_cell_[static_cast<std::size_t>(cell_of_[i])];
  }
  return by_cell;
}

void NeighborList::build_binned(const ParticleStore& s, const BoxGeometry& g, double cutoff,
                                std::size_t rows) {
  const std::size_t n = s.size();
  rows = std::min(rows, n);
  const double cut2 = cutoff * cutoff;
  const CellNeighbourhood nh = cell_neighbourhood(nc_, g);
  offsets.assign(n + 1, 0);
  // Pairs are written at `count` and kept by advancing it (no branch on the distance test, which
  // is taken about half the time in a packed bed); each row first makes room for all its
  // candidates.
  std::size_t count = 0;
  neighbors.resize(std::max<std::size_t>(neighbors.capacity(), 8 * rows + 64));
  const bool by_cell = rows_stored_by_cell(rows);
  // The geometry as locals: through the BoxGeometry reference (which the list's own stores
  // might alias) the compiler would divide by each length again for every distance test.
  const double P0 = g.period(0), P1 = g.period(1), P2 = g.period(2);
  const double iL0 = g.inv_len(0), iL1 = g.inv_len(1), iL2 = g.inv_len(2);
  const double* __restrict X = s.x.data();
  const double* __restrict Y = s.y.data();
  const double* __restrict Z = s.z.data();
  // Particles stored by cell share their neighbour cells with their predecessor.
  int cached = -1;
  int nb_cells[27];
  int n_nb = 0;
  for (std::size_t i = 0; i < rows; ++i) {
    const int c = cell_of_[i];
    if (c != cached) {
      cached = c;
      n_nb = neighbour_cells(c, nc_, nh, nb_cells);
    }
    const double xi = X[i], yi = Y[i], zi = Z[i];
    std::size_t candidates = 0;
    for (int b = 0; b < n_nb; ++b) candidates += cell_start_[nb_cells[b] + 1] - cell_start_[nb_cells[b]];
    if (count + candidates > neighbors.size()) neighbors.resize(2 * (count + candidates));
    std::uint32_t* __restrict out = neighbors.data();
    for (int b = 0; b < n_nb; ++b) {
      const int nb = nb_cells[b];
      std::uint32_t q0 = cell_start_[nb];
      if (by_cell && nb < c) q0 += rows_in_cell_[static_cast<std::size_t>(nb)];
      if (by_cell && nb == c) q0 += static_cast<std::uint32_t>(i - cell_items_[q0]) + 1;
      const std::uint32_t q1 = cell_start_[nb + 1];
      for (std::uint32_t q = q0; q < q1; ++q) {
        const std::uint32_t j = cell_items_[q];
        const double dx = min_image(xi - X[j], P0, iL0);
        const double dy = min_image(yi - Y[j], P1, iL1);
        const double dz = min_image(zi - Z[j], P2, iL2);
        out[count] = j;
        count += static_cast<std::size_t>((j > i) & (dx * dx + dy * dy + dz * dz < cut2));
      }
    }
    offsets[i + 1] = static_cast<std::uint32_t>(count);
  }
  neighbors.resize(count);
  for (std::size_t i = rows; i < n; ++i) offsets[i + 1] = offsets[i];
}

}  // namespace boycott::particles
