#include "fluid/halo_exchange.hpp"

#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "fluid/petsc_check.hpp"

namespace boycott::fluid {

namespace {
constexpr auto check = petsc_check;
}  // namespace

HaloExchange::HaloExchange(DM dm) : dm_(dm) {
  MPI_Comm dm_comm;
  check(PetscObjectGetComm(reinterpret_cast<PetscObject>(dm), &dm_comm), "PetscObjectGetComm");
  MPI_Comm_dup(dm_comm, &comm_);
  PetscInt mx, my, mz, w, xs, ys, zs, xm, ym, zm, gxs, gys, gzs, gxm, gym, gzm;
  DMBoundaryType bx, by, bz;
  check(
      DMDAGetInfo(dm, nullptr, &mx, &my, &mz, nullptr, nullptr, nullptr, nullptr, &w, &bx, &by, &bz, nullptr),
      "DMDAGetInfo");
  check(DMDAGetCorners(dm, &xs, &ys, &zs, &xm, &ym, &zm), "DMDAGetCorners");
  check(DMDAGetGhostCorners(dm, &gxs, &gys, &gzs, &gxm, &gym, &gzm), "DMDAGetGhostCorners");
  const bool periodic_y = by == DM_BOUNDARY_PERIODIC;
  const PetscInt wy = periodic_y ? w : 0;
  bool ok =
      bx == DM_BOUNDARY_PERIODIC && bz == DM_BOUNDARY_PERIODIC && (periodic_y || by == DM_BOUNDARY_NONE);
  ok = ok && xs == 0 && xm == mx && ys == 0 && ym == my && zm >= w && w >= 1;
  ok = ok && gxs == -w && gxm == mx + 2 * w && gys == -wy && gym == my + 2 * wy && gzs == zs - w &&
       gzm == zm + 2 * w;
  // every rank must take the same path (the fast one exchanges messages)
  int mine = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, comm_);
  fast_ = all == 1;
  if (!fast_) return;
  // DMDA neighbours are numbered (dz + 1) 9 + (dy + 1) 3 + (dx + 1), periodic ones included
  const PetscMPIInt* nb;
  check(DMDAGetNeighbors(dm, &nb), "DMDAGetNeighbors");
  below_ = nb[4], above_ = nb[22];
  w_ = w, wy_ = wy, nx_ = mx, ny_ = my, zm_ = zm, gxm_ = gxm, gym_ = gym;
}

HaloExchange::~HaloExchange() {
  if (comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

void HaloExchange::fill(Vec global, Vec local) const {
  if (!fast_) {
    check(DMGlobalToLocal(dm_, global, INSERT_VALUES, local), "DMGlobalToLocal");
    return;
  }
  const double* g;
  double* l;
  check(VecGetArrayRead(global, &g), "VecGetArrayRead");
  check(VecGetArray(local, &l), "VecGetArray");
  const std::size_t row = static_cast<std::size_t>(gxm_), plane = row * static_cast<std::size_t>(gym_);
  const std::size_t nx = static_cast<std::size_t>(nx_), w = static_cast<std::size_t>(w_);
  // owned rows, with their periodic x ghosts
  for (PetscInt k = 0; k < zm_; ++k) {
    double* lp = l + (k + w) * plane;
    for (PetscInt j = 0; j < ny_; ++j) {
      double* lr = lp + (j + wy_) * row;
      const double* gr = g + (static_cast<std::size_t>(k) * ny_ + j) * nx;
      std::memcpy(lr + w, gr, nx * sizeof(double));
      for (std::size_t q = 1; q <= w; ++q) {
        lr[w - q] = gr[nx - q];
        lr[w + nx - 1 + q] = gr[q - 1];
      }
    }
    // periodic y: whole ghosted rows from the far side
    for (PetscInt q = 1; q <= wy_; ++q) {
      std::memcpy(lp + (wy_ - q) * row, lp + (wy_ + ny_ - q) * row, row * sizeof(double));
      std::memcpy(lp + (wy_ + ny_ - 1 + q) * row, lp + (wy_ + q - 1) * row, row * sizeof(double));
    }
  }
  // z ghost planes: the first w owned planes go down (the upper ghosts of the rank below), the
  // last w go up; periodic in z, so on one rank they come from this slab itself
  const std::size_t count = w * plane;
  double* lower_ghost = l;
  double* first_owned = l + w * plane;
  double* last_owned = l + static_cast<std::size_t>(zm_) * plane;  // planes zm .. zm + w - 1 of the local box
  double* upper_ghost = l + (static_cast<std::size_t>(zm_) + w) * plane;
  exchange_planes(first_owned, last_owned, lower_ghost, upper_ghost, count, 0);
  check(VecRestoreArray(local, &l), "VecRestoreArray");
  check(VecRestoreArrayRead(global, &g), "VecRestoreArrayRead");
}

void HaloExchange::boundary_planes(const double* global, double* below, double* above) const {
  if (!fast_) throw std::logic_error("HaloExchange::boundary_planes: the slab decomposition is not in use");
  const std::size_t plane = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  // tags apart from fill()'s, though every rank makes the same calls in the same order
  exchange_planes(global, global + (static_cast<std::size_t>(zm_) - 1) * plane, below, above, plane, 2);
}

void HaloExchange::exchange_planes(const double* first_owned, const double* last_owned, double* lower,
                                   double* upper, std::size_t count, int tag) const {
  int self;
  MPI_Comm_rank(comm_, &self);
  if (below_ == self && above_ == self) {
    std::memcpy(lower, last_owned, count * sizeof(double));
    std::memcpy(upper, first_owned, count * sizeof(double));
    return;
  }
  MPI_Request req[4];
  const int n = static_cast<int>(count);
  MPI_Irecv(upper, n, MPI_DOUBLE, above_, tag, comm_, &req[0]);      // the above rank's first planes
  MPI_Irecv(lower, n, MPI_DOUBLE, below_, tag + 1, comm_, &req[1]);  // the below rank's last planes
  MPI_Isend(first_owned, n, MPI_DOUBLE, below_, tag, comm_, &req[2]);
  MPI_Isend(last_owned, n, MPI_DOUBLE, above_, tag + 1, comm_, &req[3]);
  MPI_Waitall(4, req, MPI_STATUSES_IGNORE);
}

}  // namespace boycott::fluid
