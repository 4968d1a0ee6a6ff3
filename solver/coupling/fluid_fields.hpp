#pragma once
// The fluid quantities the particles need, on the grid, each at its own staggered location:
// velocity u_c on c-faces (levels n and n-1), pressure gradient (plus the mean driving gradient G
// in z) on c-faces, the viscous stress divergence on c-faces (the same discrete operator the
// fluid momentum equation uses, so particle and fluid forces cancel), the material derivative
// Du/Dt on c-faces and the vorticity, at cell centres or at the grid's edges (numerics.vorticity).
// Read from the fluid solver once per CFD step; particles then sample them with their kernel
// weights (coupler.hpp).
//
// The vorticity at cell centres is a central difference of cell-centred velocities over two
// cells, omega_x(j) = (w(j+1) - w(j-1)) / 2h: a profile that alternates cell by cell has none, so
// the lift cannot see, and so cannot oppose, structure of the grid's period. At the edges of the
// staggered grid the same derivative is compact, omega_x(j - 1/2) = (w(j) - w(j-1)) / h, and on a
// no-slip wall edge one-sided from the two nearest nodes and w = 0 there, (9 w(0) - w(1)) / 3h
// (exact for a parabola): each component lives where its two derivatives are centred,
//   omega_x at (i, j - 1/2, k - 1/2): x cell, y face, z face
//   omega_y at (i - 1/2, j, k - 1/2): x face, y cell, z face
//   omega_z at (i - 1/2, j - 1/2, k): x face, y face, z cell
// and is read from there (the y faces include both walls).
//
// One MPI rank: the fields are dense copies of the whole grid with periodic wrap. Several: each
// rank holds the planes of its window (slab_exchange.hpp), filled from the ranks that own them,
// and derives the fields on the planes its particles can reach.
#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/grid_spec.hpp"

namespace boycott::fluid {
class FluidSolver;
}

namespace boycott::coupling {

class SlabExchange;

/// numerics.vorticity: true for "edges", false for "cell_centres".
inline bool edge_vorticity_from_name(const std::string& s) {
  if (s == "cell_centres") return false;
  if (s == "edges") return true;
  throw InputError(fmt::format("numerics.vorticity = \"{}\": not a vorticity of the coupling", s));
}

/// A dense grid array of nx x ny x nz values (x fastest) with periodic wrap where asked. With z
/// not periodic it is a window of planes: plane k (grid index) is stored at k - k0.
struct GridField {
  int nx = 0, ny = 0, nz = 0;
  int k0 = 0;
  bool periodic[3] = {true, true, true};
  std::vector<double> a;

  void resize(int x, int y, int z, const bool per[3], int first_plane = 0) {
    nx = x, ny = y, nz = z, k0 = first_plane;
    for (int d = 0; d < 3; ++d) periodic[d] = per[d];
    a.assign(static_cast<std::size_t>(nx) * ny * nz, 0.0);
  }
  std::size_t plane_size() const { return static_cast<std::size_t>(nx) * ny; }
  static int wrap(int i, int n) {
    // Stencils reach at most two cells outside: one add or subtract instead of an integer
    // division (the % made index() a third of the field update and sampling time).
    if (i >= 0 && i < n) return i;
    if (i < 0 && i >= -n) return i + n;
    if (i >= n && i < 2 * n) return i - n;
    i %= n;
    return i < 0 ? i + n : i;
  }
  std::size_t index(int i, int j, int k) const {
    if (periodic[0]) i = wrap(i, nx);
    if (periodic[1]) j = wrap(j, ny);
    if (periodic[2])
      k = wrap(k, nz);
    else
      k -= k0;
    return (static_cast<std::size_t>(k) * ny + j) * nx + i;
  }
  double& at(int i, int j, int k) { return a[index(i, j, k)]; }
  double at(int i, int j, int k) const { return a[index(i, j, k)]; }
};

class FluidFields {
 public:
  /// window: the planes this rank holds on several ranks (nullptr: one rank, the whole grid).
  /// edge_vorticity: the vorticity at the grid's edges (see above) instead of cell centres.
  FluidFields(const GridSpec& g, bool top_slip, const SlabExchange* window = nullptr,
              bool edge_vorticity = false);

  /// Reads velocity, pressure and nu_t from the solver at its current level and derives the
  /// fields above. `dt_s` is the step that led to this level (for Du/Dt; 0 = first call, then
  /// the time derivative is taken as zero).
  void update(fluid::FluidSolver& fs, double dt_s, bool need_viscous, bool need_material,
              bool need_vorticity);

  const GridSpec& grid() const { return g_; }
  /// Face fields per component c (0 u on x-faces, 1 v on y-faces, 2 w on z-faces). With y walls
  /// the v field has ny + 1 rows; rows 0 and ny are the walls (v = 0).
  const GridField& velocity(int c) const { return u_[c]; }
  const GridField& pressure_gradient(int c) const { return gradp_[c]; }   ///< Pa/m, includes G e_z
  const GridField& viscous(int c) const { return visc_[c]; }              ///< div tau / rho, m/s^2
  const GridField& material_derivative(int c) const { return dudt_[c]; }  ///< m/s^2
  /// 1/s: at cell centres, or (edge_vorticity()) at the edges above, component c's layout
  /// having the y faces (ny + 1 rows with walls) for c = 0 and 2.
  const GridField& vorticity(int c) const { return vort_[c]; }
  bool edge_vorticity() const { return edge_vorticity_; }

  /// The velocity read at the last update (the next update's previous level, for Du/Dt), for
  /// checkpoints: u, v, w arrays of this rank's own planes and whether a previous level exists.
  std::vector<std::vector<double>> export_state() const;
  /// The same arrays over the whole grid (all ranks' planes, as export_state gives them on one).
  void import_state(const std::vector<std::vector<double>>& st);

 private:
  /// u_c at face node (i,j,k) with the wall rule in y: beyond a wall the tangential velocity is
  /// mirrored (-u no-slip, +u slip top) and v is zero on the wall rows.
  double uval(int c, int i, int j, int k) const;
  double nu_cell(int i, int j, int k) const;

  /// A copy of a field with two layers of padding on every side, filled by the field's own
  /// boundary rule (periodic wrap, wall mirror), so that the stencils below read it without the
  /// wrap and wall branches of GridField::at and uval (they were about half of a coupled step's
  /// field update). The stencils reach one node out in each direction, corners included.
  struct Padded {
    static constexpr int kPad = 2;
    int nx = 0, ny = 0;  // padded extents in x and y
    std::vector<double> a;
    double operator()(int i, int j, int k) const {
      return a[(static_cast<std::size_t>(k + kPad) * ny + (j + kPad)) * nx + (i + kPad)];
    }
  };
  template <class Rule>
  static void fill_padded(Padded& dst, int nx, int ny, int nz, Rule&& value);

  // The steps of update(): the solver's fields copied in, their padded copies, the face fields
  // of each component (the rows' stencil reads gathered first), the wall rows of v, the vorticity.
  struct ViscousTerm;
  struct ConvectionTerm;
  void read_solver_fields(fluid::FluidSolver& fs);
  void fill_padded_copies();
  /// Row (j, k) of a padded copy, at i = 0.
  const double* padded_row(const Padded& P, int j, int k) const;
  void update_face_fields(int c, double G, double dt_s, bool first, bool need_viscous, bool need_material);
  /// The reads of the six neighbour terms of component c's viscous operator in row (j, k).
  void viscous_terms(int c, int j, int k, ViscousTerm (&terms)[6]) const;
  /// The reads of the three terms of component c's convective derivative in row (j, k).
  void convection_terms(int c, int j, int k, ConvectionTerm (&cv)[3]) const;
  void copy_wall_rows_of_v();
  void update_centre_vorticity();
  void update_edge_vorticity();

  GridSpec g_;
  bool walls_, top_slip_, edge_vorticity_;
  const SlabExchange* window_ = nullptr;
  // Planes [kb_, ke_) get the face-derived fields, [kb_, kce_) the vorticity; kofs_ is the grid
  // plane of the padded arrays' plane 0.
  int kb_ = 0, ke_ = 0, kce_ = 0, kofs_ = 0;
  double rho_ = 1000.0, nu_ = 1e-6;
  GridField u_[3], uprev_[3], gradp_[3], visc_[3], dudt_[3], vort_[3], p_, nut_;
  Padded upad_[3], ppad_, nupad_;  // uval, p and nu + nu_t, padded
  bool have_prev_ = false;
};

// The per-node reads of the field derivations, inline for both files that derive them.
inline double FluidFields::uval(int c, int i, int j, int k) const {
  if (walls_) {
    const int ny = (int)g_.n[1];
    if (c == 1) {
      if (j < 0) return -u_[1].at(i, -j, k);
      if (j > ny) return -u_[1].at(i, 2 * ny - j, k);
    } else {
      if (j < 0) return -u_[c].at(i, -1 - j, k);
      if (j >= ny) return (top_slip_ ? 1.0 : -1.0) * u_[c].at(i, 2 * ny - 1 - j, k);
    }
  }
  return u_[c].at(i, j, k);
}

inline const double* FluidFields::padded_row(const Padded& P, int j, int k) const {
  // The value at (i + di, j, k) of a padded copy is padded_row(P, j, k)[i + di]: each stencil
  // read is one row pointer, set once per (j, k) row, plus the cell index; the sums are the same
  // as reading node by node, in the same order.
  return P.a.data() +
         (static_cast<std::size_t>(k - kofs_ + Padded::kPad) * P.ny +
          static_cast<std::size_t>(j + Padded::kPad)) *
             P.nx +
         Padded::kPad;
}

}  // namespace boycott::coupling
