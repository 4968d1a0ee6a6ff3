#pragma once
// The z-planes of the coupling's grid arrays beyond a rank's own slab. On several ranks each
// rank keeps its arrays over a window of planes [z0 - below, z1 + above) around the planes
// [z0, z1) it owns (the fluid's z-slab): its particles sample the fluid there and deposit their
// volume and forces there, up to their kernel's reach and the fluid stencils' width. The window
// may wrap around the periodic z direction, onto other ranks' planes or onto its own.
//
// fill() copies the owners' values into a window; sum_to_owned() adds every rank's window
// planes into the owners' planes, in a fixed order (the rank's own planes, then its own window's
// wrapped copies, then the other ranks' in rank order), so that a run repeats bit for bit on the
// same number of ranks.
#include <mpi.h>

#include <cstddef>
#include <vector>

namespace boycott::coupling {

class SlabExchange {
 public:
  /// slab_begin: the first plane of each rank, in rank order, then nz (size ranks + 1).
  SlabExchange(MPI_Comm comm, std::vector<int> slab_begin, int below, int above);

  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int ranks() const { return static_cast<int>(slab_begin_.size()) - 1; }
  int nz() const { return slab_begin_.back(); }
  /// This rank's slab [own_begin, own_end) and window [window_begin, window_begin + planes).
  int own_begin() const { return slab_begin_[rank_]; }
  int own_end() const { return slab_begin_[rank_ + 1]; }
  int window_begin() const { return window_begin_of(rank_); }
  int window_planes() const { return window_planes_of(rank_); }

  /// window[p][...] = the owner's value of plane window_begin + p (periodic), plane_size values
  /// per plane; owned: this rank's planes [own_begin, own_end).
  void fill(const double* owned, double* window, std::size_t plane_size) const;
  /// owned[q] = the sum over every window plane that is plane own_begin + q (all ranks).
  void sum_to_owned(const double* window, double* owned, std::size_t plane_size) const;

 private:
  int window_begin_of(int r) const { return slab_begin_[r] - below_; }
  int window_planes_of(int r) const { return slab_begin_[r + 1] - slab_begin_[r] + below_ + above_; }
  int owner(int plane) const;  ///< plane in [0, nz)
  int wrap(int plane) const;

  MPI_Comm comm_;
  int rank_ = 0;
  std::vector<int> slab_begin_;
  int below_, above_;
  // Per other rank q: the (window plane of q, my owned plane) pairs I send it (fill) and the
  // (my window plane, owned plane of q) pairs I send it (sum), each in q's window order.
  std::vector<std::vector<std::pair<int, int>>> fill_send_, fill_recv_, sum_send_, sum_recv_;
};

}  // namespace boycott::coupling
