#include "coupling/slab_exchange.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace boycott::coupling {

namespace {

/// Sends out[r] to rank r; returns what arrives from each rank, in rank order.
std::vector<double> alltoallv(MPI_Comm comm, const std::vector<std::vector<double>>& out) {
  const int size = static_cast<int>(out.size());
  std::vector<int> sc(size), sd(size), rc(size), rd(size);
  int total_out = 0;
  for (int r = 0; r < size; ++r)
    sc[r] = static_cast<int>(out[r].size()), sd[r] = total_out, total_out += sc[r];
  MPI_Alltoall(sc.data(), 1, MPI_INT, rc.data(), 1, MPI_INT, comm);
  int total_in = 0;
  for (int r = 0; r < size; ++r) rd[r] = total_in, total_in += rc[r];
  std::vector<double> send;
  send.reserve(static_cast<std::size_t>(total_out));
  for (const auto& b : out) send.insert(send.end(), b.begin(), b.end());
  std::vector<double> recv(static_cast<std::size_t>(total_in));
  MPI_Alltoallv(send.data(), sc.data(), sd.data(), MPI_DOUBLE, recv.data(), rc.data(), rd.data(), MPI_DOUBLE,
                comm);
  return recv;
}

}  // namespace

SlabExchange::SlabExchange(MPI_Comm comm, std::vector<int> slab_begin, int below, int above)
    : comm_(comm), slab_begin_(std::move(slab_begin)), below_(below), above_(above) {
  MPI_Comm_rank(comm_, &rank_);
  const int n = ranks();
  int size = 1;
  MPI_Comm_size(comm_, &size);
  if (size != n) throw std::logic_error("SlabExchange: one slab per rank expected");
  fill_send_.assign(n, {});
  fill_recv_.assign(n, {});
  sum_send_.assign(n, {});
  sum_recv_.assign(n, {});
  for (int q = 0; q < n; ++q)
    for (int p = 0; p < window_planes_of(q); ++p) {
      const int g = wrap(window_begin_of(q) + p), o = owner(g), local = g - slab_begin_[o];
      if (q == rank_) {
        if (o == rank_) continue;  // handled by self_ below
        fill_recv_[o].emplace_back(p, local);
        sum_send_[o].emplace_back(p, local);
      } else if (o == rank_) {
        fill_send_[q].emplace_back(p, local);
        sum_recv_[q].emplace_back(p, local);
      }
    }
}

int SlabExchange::wrap(int plane) const {
  const int n = nz();
  plane %= n;
  return plane < 0 ? plane + n : plane;
}

int SlabExchange::owner(int plane) const {
  const auto it = std::upper_bound(slab_begin_.begin() + 1, slab_begin_.end() - 1, plane);
  return static_cast<int>(it - (slab_begin_.begin() + 1));
}

void SlabExchange::fill(const double* owned, double* window, std::size_t ps) const {
  const int planes = window_planes();
  for (int p = 0; p < planes; ++p) {
    const int g = wrap(window_begin() + p);
    if (owner(g) == rank_)
      std::copy(owned + (g - own_begin()) * ps, owned + (g - own_begin() + 1) * ps, window + p * ps);
  }
  std::vector<std::vector<double>> out(fill_send_.size());
  for (std::size_t r = 0; r < out.size(); ++r)
    for (const auto& [p, local] : fill_send_[r])
      out[r].insert(out[r].end(), owned + local * ps, owned + (local + 1) * ps);
  const auto in = alltoallv(comm_, out);
  std::size_t at = 0;
  for (const auto& list : fill_recv_)
    for (const auto& [p, local] : list) {
      std::copy(in.begin() + static_cast<std::ptrdiff_t>(at),
                in.begin() + static_cast<std::ptrdiff_t>(at + ps), window + p * ps);
      at += ps;
    }
}

void SlabExchange::sum_to_owned(const double* window, double* owned, std::size_t ps) const {
  const int own = own_end() - own_begin();
  std::copy(window + below_ * ps, window + (below_ + own) * ps, owned);
  // Wrapped copies of this rank's own planes in its own window (tiny grids).
  const int planes = window_planes();
  for (int p = 0; p < planes; ++p) {
    if (p >= below_ && p < below_ + own) continue;
    const int g = wrap(window_begin() + p);
    if (owner(g) != rank_) continue;
    double* dst = owned + (g - own_begin()) * ps;
    for (std::size_t k = 0; k < ps; ++k) dst[k] += window[p * ps + k];
  }
  std::vector<std::vector<double>> out(sum_send_.size());
  for (std::size_t r = 0; r < out.size(); ++r)
    for (const auto& [p, local] : sum_send_[r])
      out[r].insert(out[r].end(), window + p * ps, window + (p + 1) * ps);
  const auto in = alltoallv(comm_, out);
  std::size_t at = 0;
  for (const auto& list : sum_recv_)
    for (const auto& [p, local] : list) {
      double* dst = owned + local * ps;
      for (std::size_t k = 0; k < ps; ++k) dst[k] += in[at + k];
      at += ps;
    }
}

}  // namespace boycott::coupling
