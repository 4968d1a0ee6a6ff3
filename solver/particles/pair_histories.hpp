#pragma once
// The tangential springs of the particle pairs in contact, kept per contact: what the contact
// loop reads and updates, carried from one force evaluation to the next while a pair stays in
// contact, and handed over by the particles' global ids across list rebuilds, migrations and
// checkpoints (contact_history.cpp restores them into a new list).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace boycott::particles {

/// Springs keyed by the global ids of their two particles (a < b), each seen from a: what
/// survives a list rebuild, a migration between ranks or a checkpoint.
struct CarriedHistories {
  std::vector<std::int64_t> a, b;
  std::vector<double> h;  ///< x, y, z of pair q at 3q, m
  void clear() {
    a.clear();
    b.clear();
    h.clear();
  }
};

class PairHistories {
 public:
  /// The springs of this evaluation's nc contacts, the list slots slot[0..nc) in increasing
  /// order, from those of the last one: a pair still in contact keeps its spring, one that has
  /// just touched starts at zero, and one that separated is dropped (its spring reset). One merge
  /// of two sorted lists, O(contacts), sequential in memory.
  void carry_to_contacts(const std::uint32_t* slot, std::size_t nc);
  /// Contact q's spring (seen from its row's particle i), m: x, y, z at 3q, updated in place by
  /// the contact loop.
  double* data() { return h_.data(); }
  /// The list slots of the contacts, in increasing order.
  const std::vector<std::uint32_t>& slots() const { return slots_; }
  const double* of_contact(std::size_t q) const { return &h_[3 * q]; }
  /// The spring of list slot p, or null where p is not a contact; `q` (0 at the start) walks the
  /// contacts for slots visited in increasing order.
  const double* of_slot(std::uint32_t p, std::size_t& q) const;

  /// Starts over for a new list (the springs are then given back with add()).
  void clear();
  /// List slot p, whose row particle has the lower id when sign = 1 (the higher: -1), takes the
  /// carried spring hq (seen from the lower id); slots must come in increasing order.
  void add(std::uint32_t p, double sign, const double* hq);
  /// The contacts with a spring, by their particles' global ids (id of each stored particle,
  /// row particle and partner of each list slot).
  void collect(const std::int64_t* id, const std::uint32_t* row_of_slot, const std::uint32_t* partner,
               CarriedHistories& out) const;

 private:
  std::vector<std::uint32_t> slots_;
  std::vector<double> h_, next_;
};

}  // namespace boycott::particles
