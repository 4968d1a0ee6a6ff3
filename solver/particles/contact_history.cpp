// Contact-history bookkeeping: the tangential spring of each pair (keyed by global ids, so
// that it survives reordering, list rebuilds and restarts) and of each particle at each wall,
// reset when a contact ends.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "particles/dem_system.hpp"

namespace boycott::particles {

namespace {
std::uint64_t pair_key(std::int64_t a, std::int64_t b) {
  return (static_cast<std::uint64_t>(a) << 32) ^ static_cast<std::uint64_t>(b);
}
}  // namespace

void DemSystem::collect_histories() {
  // Contacts with a shear history, keyed by global ids so they survive reordering and rebuilds.
  carry_a_.clear();
  carry_b_.clear();
  carry_h_.clear();
  const std::size_t n = s_.size();
  if (nl_.offsets.size() != n + 1) return;
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      if (h_[3 * p] == 0.0 && h_[3 * p + 1] == 0.0 && h_[3 * p + 2] == 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[nl_.neighbors[p]];
      const double sg = a < b ? 1.0 : -1.0;
      carry_a_.push_back(std::min(a, b));
      carry_b_.push_back(std::max(a, b));
      carry_h_.insert(carry_h_.end(), {sg * h_[3 * p], sg * h_[3 * p + 1], sg * h_[3 * p + 2]});
    }
}

void DemSystem::restore_histories(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                                  const std::vector<double>& h) {
  const std::size_t np = nl_.pair_count();
  h_.assign(3 * np, 0.0);
  // A new list: the pairs with a history (restored below) are the ones forget_separated_pairs
  // must look at next, and the flat row index of each slot is refreshed.
  pair_mark_.assign(np, 0);
  prev_contacts_.clear();
  pair_i_.resize(np);
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p)
      pair_i_[p] = static_cast<std::uint32_t>(i);
  if (ida.empty()) return;
  // Sorted (key, slot) table; only pairs that overlap now can carry a history (it is reset
  // whenever a pair separates), so only those are looked up.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> table(ida.size());
  for (std::size_t q = 0; q < ida.size(); ++q)
    table[q] = {pair_key(ida[q], idb[q]), static_cast<std::uint32_t>(q)};
  std::sort(table.begin(), table.end());
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = nl_.offsets[i]; p < nl_.offsets[i + 1]; ++p) {
      const std::uint32_t j = nl_.neighbors[p];
      if (pair_overlap(i, j) <= 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[j];
      const std::uint64_t key = pair_key(std::min(a, b), std::max(a, b));
      auto it = std::lower_bound(table.begin(), table.end(), std::pair<std::uint64_t, std::uint32_t>{key, 0});
      if (it == table.end() || it->first != key) continue;
      const double sg = a < b ? 1.0 : -1.0;
      h_[3 * p] = sg * h[3 * it->second];
      h_[3 * p + 1] = sg * h[3 * it->second + 1];
      h_[3 * p + 2] = sg * h[3 * it->second + 2];
      pair_mark_[p] = 1;
      prev_contacts_.push_back(p);
    }
}

void DemSystem::rescan_wall_contacts() {
  // After a reordering the remembered wall contacts are stale: every particle with a wall
  // history is one (the history is zero for all others).
  prev_wall_contacts_.assign(cfg_.walls.size(), {});
  for (std::size_t w = 0; w < cfg_.walls.size(); ++w)
    for (std::size_t i = 0; i < whx_[w].size(); ++i)
      if (whx_[w][i] != 0.0 || why_[w][i] != 0.0 || whz_[w][i] != 0.0)
        prev_wall_contacts_[w].push_back(static_cast<std::uint32_t>(i));
}

void DemSystem::forget_separated_pairs(std::size_t nc) {
  // A pair's shear spring is reset when it separates (h_ is zero for every pair not in
  // contact). Only pairs that were in contact at the last evaluation can have just separated,
  // so only they are visited: O(contacts), not O(list pairs), per step.
  pair_mark_.resize(nl_.pair_count(), 0);
  for (std::size_t k = 0; k < nc; ++k) pair_mark_[contact_p_[k]] |= 2;
  for (std::uint32_t p : prev_contacts_)
    if (!(pair_mark_[p] & 2)) h_[3 * p] = h_[3 * p + 1] = h_[3 * p + 2] = 0.0;
  for (std::uint32_t p : prev_contacts_) pair_mark_[p] = 0;
  prev_contacts_.assign(contact_p_.begin(), contact_p_.begin() + static_cast<std::ptrdiff_t>(nc));
  for (std::uint32_t p : prev_contacts_) pair_mark_[p] = 1;
}

}  // namespace boycott::particles
