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
  // Only the last evaluation's contacts (or the last restore's) hold a spring: O(contacts).
  if (verlet_.list.offsets.size() != s_.size() + 1) {
    carry_.springs.clear();
    return;
  }
  pairs_.springs.collect(s_.id.data(), verlet_.row_of_slot.data(), verlet_.list.neighbors.data(),
                         carry_.springs);
}

void DemSystem::restore_histories(const std::vector<std::int64_t>& ida, const std::vector<std::int64_t>& idb,
                                  const std::vector<double>& h) {
  const std::size_t np = verlet_.list.pair_count();
  // A new list: the pairs with a history (restored below, in slot order) stand for the last
  // evaluation's contacts, and the flat row index of each slot is refreshed.
  pairs_.springs.clear();
  verlet_.row_of_slot.resize(np);
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = verlet_.list.offsets[i]; p < verlet_.list.offsets[i + 1]; ++p)
      verlet_.row_of_slot[p] = static_cast<std::uint32_t>(i);
  if (ida.empty()) return;
  if (!restore_histories_by_row(ida, idb, h)) restore_histories_by_key(ida, idb, h);
}

void DemSystem::restore_history(std::uint32_t p, std::size_t i, std::uint32_t j, const double* hq) {
  // The carried history is seen from the lower id; the list slot sees it from its row i.
  pairs_.springs.add(p, s_.id[i] < s_.id[j] ? 1.0 : -1.0, hq);
}

bool DemSystem::restore_histories_by_row(const std::vector<std::int64_t>& ida,
                                         const std::vector<std::int64_t>& idb, const std::vector<double>& h) {
  // Each carried pair of ids goes to the list row it belongs to now (its lower storage index),
  // by a counting sort in carried order; each list pair then scans its row's few entries. The
  // rows are visited in storage (spatial) order, so this stays in cache where a global search
  // table would miss on every lookup. Needs each stored id once (ghost images of one particle
  // twice would be ambiguous) and ids of the order of the particle count.
  const std::size_t n = s_.size();
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::int64_t max_id = -1;
  for (std::int64_t v : s_.id) max_id = std::max(max_id, v);
  if (max_id < 0 || static_cast<std::uint64_t>(max_id) > 8 * static_cast<std::uint64_t>(n) + 1024)
    return false;
  carry_.slot_of_id.assign(static_cast<std::size_t>(max_id) + 1, kNone);
  for (std::size_t k = 0; k < n; ++k) {
    std::uint32_t& slot = carry_.slot_of_id[static_cast<std::size_t>(s_.id[k])];
    if (slot != kNone) return false;
    slot = static_cast<std::uint32_t>(k);
  }
  auto slot_of = [&](std::int64_t id) {
    return id < 0 || id > max_id ? kNone : carry_.slot_of_id[static_cast<std::size_t>(id)];
  };
  carry_.row_start.assign(n + 1, 0);
  for (std::size_t q = 0; q < ida.size(); ++q) {
    const std::uint32_t a = slot_of(ida[q]), b = slot_of(idb[q]);
    if (a != kNone && b != kNone) ++carry_.row_start[std::min(a, b) + 1];
  }
  for (std::size_t i = 0; i < n; ++i) carry_.row_start[i + 1] += carry_.row_start[i];
  carry_.row_partner.resize(carry_.row_start[n]);
  carry_.row_entry.resize(carry_.row_start[n]);
  {
    std::vector<std::uint32_t>& fill = carry_.row_fill;
    fill.assign(carry_.row_start.begin(), carry_.row_start.end() - 1);
    for (std::size_t q = 0; q < ida.size(); ++q) {
      const std::uint32_t a = slot_of(ida[q]), b = slot_of(idb[q]);
      if (a == kNone || b == kNone) continue;
      const std::uint32_t at = fill[std::min(a, b)]++;
      carry_.row_partner[at] = std::max(a, b);
      carry_.row_entry[at] = static_cast<std::uint32_t>(q);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t e0 = carry_.row_start[i], e1 = carry_.row_start[i + 1];
    if (e0 == e1) continue;
    for (std::uint32_t p = verlet_.list.offsets[i]; p < verlet_.list.offsets[i + 1]; ++p) {
      const std::uint32_t j = verlet_.list.neighbors[p];
      // The first carried entry of this pair, as the search by key takes it.
      std::uint32_t e = e0;
      while (e < e1 && carry_.row_partner[e] != j) ++e;
      // Only pairs that overlap now keep a history (it is reset whenever a pair separates).
      if (e == e1 || pair_overlap(i, j) <= 0.0) continue;
      restore_history(p, i, j, &h[3 * static_cast<std::size_t>(carry_.row_entry[e])]);
    }
  }
  return true;
}

void DemSystem::restore_histories_by_key(const std::vector<std::int64_t>& ida,
                                         const std::vector<std::int64_t>& idb, const std::vector<double>& h) {
  // Sorted (key, entry) table; only pairs that overlap now can carry a history (it is reset
  // whenever a pair separates), so only those are looked up.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> table(ida.size());
  for (std::size_t q = 0; q < ida.size(); ++q)
    table[q] = {pair_key(ida[q], idb[q]), static_cast<std::uint32_t>(q)};
  std::sort(table.begin(), table.end());
  for (std::size_t i = 0; i < s_.size(); ++i)
    for (std::uint32_t p = verlet_.list.offsets[i]; p < verlet_.list.offsets[i + 1]; ++p) {
      const std::uint32_t j = verlet_.list.neighbors[p];
      if (pair_overlap(i, j) <= 0.0) continue;
      const std::int64_t a = s_.id[i], b = s_.id[j];
      const std::uint64_t key = pair_key(std::min(a, b), std::max(a, b));
      auto it = std::lower_bound(table.begin(), table.end(), std::pair<std::uint64_t, std::uint32_t>{key, 0});
      if (it == table.end() || it->first != key) continue;
      restore_history(p, i, j, &h[3 * static_cast<std::size_t>(it->second)]);
    }
}

}  // namespace boycott::particles
