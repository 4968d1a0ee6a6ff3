// Which listed pairs overlap at a force evaluation, the first pass of the force loop. A
// branch-free test over pairs writes a byte per pair (it vectorises), then the flagged pairs are
// appended to the contact list (flag_compress.hpp). The test runs over the near pairs (dem_parts.hpp,
// NearPairs): the list pairs whose surfaces were within a margin when they were last filtered,
// renewed when some particle may have moved half the margin. In a suspension most list pairs are
// apart (8 in 9 on the LIGGGHTS bench; 2.5 list pairs per particle and 0.8 near at 0.1 mm in the
// vertical channel, half of the list in a settled bed, docs/performance.md), so with the renewals
// the test reads about two fifths to three fifths of the list per step. The near pairs keep the list's order
// and every pair that can touch, so the contacts, their order and every result are the bits of a test over
// the whole list.
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "particles/dem_system.hpp"
#include "particles/displacement_bound.hpp"
#include "particles/flag_compress.hpp"
#include "particles/min_image.hpp"

namespace boycott::particles {

namespace {
/// flag[p] = whether the centres of pair p (particle pair_i[p] and nb[p]) are closer than the sum
/// of their radii plus `margin` (m). The periodic directions are template flags so that the loop
/// body has no branch at all; so is UR, all radii equal (their sum rsum_u then replaces two
/// gathers per pair). With margin 0 the bound is the sum itself (x + 0 is x).
template <bool PX, bool PY, bool PZ, bool UR>
void flag_within(std::size_t np, const std::uint32_t* __restrict pair_i, const std::uint32_t* __restrict nb,
                 const double* __restrict x, const double* __restrict y, const double* __restrict z,
                 const double* __restrict rad, double rsum_u, double margin, const std::array<double, 3>& len,
                 std::uint8_t* __restrict flag) {
  const double Lx = len[0], Ly = len[1], Lz = len[2];
  const double iLx = 1.0 / Lx, iLy = 1.0 / Ly, iLz = 1.0 / Lz;
  for (std::size_t p = 0; p < np; ++p) {
    const std::uint32_t i = pair_i[p], j = nb[p];
    double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
    if constexpr (PX) dx = min_image(dx, Lx, iLx);
    if constexpr (PY) dy = min_image(dy, Ly, iLy);
    if constexpr (PZ) dz = min_image(dz, Lz, iLz);
    double rsum = rsum_u;
    if constexpr (!UR) rsum = rad[i] + rad[j];
    const double reach = rsum + margin;
    flag[p] = dx * dx + dy * dy + dz * dz < reach * reach;
  }
}

using FlagWithinFn = void (*)(std::size_t, const std::uint32_t*, const std::uint32_t*, const double*,
                              const double*, const double*, const double*, double, double,
                              const std::array<double, 3>&, std::uint8_t*);
// Indexed by periodic x | y << 1 | z << 2 | uniform radii << 3.
constexpr auto kFlagWithin = []<std::size_t... B>(std::index_sequence<B...>) {
  return std::array<FlagWithinFn, sizeof...(B)>{
      flag_within<(B & 1) != 0, (B & 2) != 0, (B & 4) != 0, (B & 8) != 0>...};
}
(std::make_index_sequence<16>{});
}  // namespace

std::size_t DemSystem::find_pair_contacts() {
  const std::size_t np = verlet_.list.pair_count();
  pairs_.row.resize(np);
  pairs_.slot.resize(np);
  pairs_.flag.resize(np);
  // Equal radii (and moments of inertia): the usual monodisperse case, where the loops take
  // them as constants (the same values, so the same bits) instead of gathering them per pair.
  const double Ru = uniform_.radius_m;
  const auto& per = cfg_.box.periodic;
  const FlagWithinFn within =
      kFlagWithin[(per[0] ? 1 : 0) | (per[1] ? 2 : 0) | (per[2] ? 4 : 0) | (Ru > 0.0 ? 8 : 0)];
  auto test = [&](std::size_t count, const std::uint32_t* rows, const std::uint32_t* partners,
                  double margin) {
    within(count, rows, partners, s_.x.data(), s_.y.data(), s_.z.data(), s_.radius.data(), Ru + Ru, margin,
           cfg_.box.len, pairs_.flag.data());
  };
  const std::uint32_t* row_of_slot = verlet_.row_of_slot.data();
  std::size_t nc = 0;
  if (near_.margin_m > 0.0) {
    if (!near_pairs_exact()) {
      test(np, row_of_slot, verlet_.list.neighbors.data(), near_.margin_m);
      renew_near_pairs(np);
    }
    const std::size_t nq = near_.slot.size();
    test(nq, near_.row.data(), near_.partner.data(), 0.0);
    nc = compress_flagged(nq, pairs_.flag.data(), near_.row.data(), pairs_.row.data(), pairs_.slot.data());
    // from the near pair's index to its list slot (the springs and the partner are the slot's)
    std::uint32_t* __restrict slot = pairs_.slot.data();
    const std::uint32_t* __restrict near_slot = near_.slot.data();
    for (std::size_t k = 0; k < nc; ++k) slot[k] = near_slot[slot[k]];
  } else {
    test(np, row_of_slot, verlet_.list.neighbors.data(), 0.0);
    nc = compress_flagged(np, pairs_.flag.data(), row_of_slot, pairs_.row.data(), pairs_.slot.data());
  }
  pairs_.springs.carry_to_contacts(pairs_.slot.data(), nc);
  return nc;
}

bool DemSystem::near_pairs_exact() const {
  // A pair left out was at least the margin apart at the renewal; it can touch only after its
  // distance has shrunk by the margin, which needs some particle to have moved half the margin
  // from a common displacement (displacement_bound.hpp; the box's centre is the one tested).
  // Ghost copies count too: their positions are refreshed every step. A pass of its own: taken
  // inside the fused kick instead (while the drifted block is in L1, as the rebuild test's box),
  // the kick's share of a bench_dem run at 120 000 particles grew by more (3.8 % of the run) than
  // this pass takes (2.5 %; perf, docs/performance.md).
  if (!near_.fresh) return false;
  const DisplacementSpread sp = displacement_box(s_.size(), s_.x.data(), s_.y.data(), s_.z.data(),
                                                 near_.ref_x.data(), near_.ref_y.data(), near_.ref_z.data());
  return box_within_half_skin(sp, near_.margin_m);
}

void DemSystem::renew_near_pairs(std::size_t np) {
  // pairs_.flag holds the test of every list pair against the margin.
  near_.row.resize(np);
  near_.slot.resize(np);
  const std::size_t nq = compress_flagged(np, pairs_.flag.data(), verlet_.row_of_slot.data(),
                                          near_.row.data(), near_.slot.data());
  near_.row.resize(nq);
  near_.slot.resize(nq);
  near_.partner.resize(nq);
  const std::uint32_t* nb = verlet_.list.neighbors.data();
  for (std::size_t q = 0; q < nq; ++q) near_.partner[q] = nb[near_.slot[q]];
  near_.ref_x.assign(s_.x.begin(), s_.x.end());
  near_.ref_y.assign(s_.y.begin(), s_.y.end());
  near_.ref_z.assign(s_.z.begin(), s_.z.end());
  near_.fresh = true;
  ++near_.renewals;
}

}  // namespace boycott::particles
