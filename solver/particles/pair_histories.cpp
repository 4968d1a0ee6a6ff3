#include "particles/pair_histories.hpp"

#include <algorithm>

namespace boycott::particles {

void PairHistories::carry_to_contacts(const std::uint32_t* slot, std::size_t nc) {
  next_.resize(3 * nc);
  const std::uint32_t* __restrict prev = slots_.data();
  const double* __restrict from = h_.data();
  double* __restrict to = next_.data();
  const std::size_t nprev = slots_.size();
  std::size_t q = 0;
  for (std::size_t k = 0; k < nc; ++k) {
    while (q < nprev && prev[q] < slot[k]) ++q;
    const bool kept = q < nprev && prev[q] == slot[k];
    to[3 * k] = kept ? from[3 * q] : 0.0;
    to[3 * k + 1] = kept ? from[3 * q + 1] : 0.0;
    to[3 * k + 2] = kept ? from[3 * q + 2] : 0.0;
  }
  h_.swap(next_);
  slots_.assign(slot, slot + nc);
}

const double* PairHistories::of_slot(std::uint32_t p, std::size_t& q) const {
  while (q < slots_.size() && slots_[q] < p) ++q;
  return q < slots_.size() && slots_[q] == p ? &h_[3 * q] : nullptr;
}

void PairHistories::clear() {
  slots_.clear();
  h_.clear();
}

void PairHistories::add(std::uint32_t p, double sign, const double* hq) {
  h_.insert(h_.end(), {sign * hq[0], sign * hq[1], sign * hq[2]});
  slots_.push_back(p);
}

void PairHistories::collect(const std::int64_t* id, const std::uint32_t* row_of_slot,
                            const std::uint32_t* partner, CarriedHistories& out) const {
  out.clear();
  // In increasing slot order: the same pairs in the same order as a scan of the whole list.
  for (std::size_t q = 0; q < slots_.size(); ++q) {
    const double* hq = &h_[3 * q];
    if (hq[0] == 0.0 && hq[1] == 0.0 && hq[2] == 0.0) continue;
    const std::uint32_t p = slots_[q];
    const std::int64_t a = id[row_of_slot[p]], b = id[partner[p]];
    const double sg = a < b ? 1.0 : -1.0;
    out.a.push_back(std::min(a, b));
    out.b.push_back(std::max(a, b));
    out.h.insert(out.h.end(), {sg * hq[0], sg * hq[1], sg * hq[2]});
  }
}

}  // namespace boycott::particles
