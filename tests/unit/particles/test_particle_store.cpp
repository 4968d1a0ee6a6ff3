// The in-place selection of particles that migration uses, against the permute-then-resize it
// replaced.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "particles/particle_store.hpp"

namespace boycott::particles {
namespace {

ParticleStore random_store(std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ParticleStore s;
  for (std::size_t i = 0; i < n; ++i)
    s.add(static_cast<std::int64_t>(1000 + i), u(rng), u(rng), u(rng), 1e-3, 2500.0);
  s.for_each_array([&](std::vector<double>& a) {
    for (double& v : a) v = u(rng);
  });
  return s;
}

void expect_same(ParticleStore a, ParticleStore b) {
  ASSERT_EQ(a.id, b.id);
  EXPECT_EQ(a.n_local, b.n_local);
  std::vector<std::vector<double>> va, vb;
  a.for_each_array([&](std::vector<double>& v) { va.push_back(v); });
  b.for_each_array([&](std::vector<double>& v) { vb.push_back(v); });
  ASSERT_EQ(va.size(), vb.size());
  for (std::size_t k = 0; k < va.size(); ++k) EXPECT_EQ(va[k], vb[k]) << "array " << k;
}

TEST(ParticleStore, KeepIncreasingIsPermuteThenResize) {
  std::mt19937_64 rng(7);
  for (std::size_t n : {0u, 1u, 5u, 64u, 1000u})
    for (double p_keep : {0.0, 0.3, 0.97, 1.0}) {
      const ParticleStore s = random_store(n, rng);
      std::bernoulli_distribution keep_it(p_keep);
      std::vector<std::size_t> keep;
      for (std::size_t i = 0; i < n; ++i)
        if (keep_it(rng)) keep.push_back(i);
      ParticleStore expected = s, got = s;
      expected.permute(keep);
      expected.resize(keep.size());
      got.keep_increasing(keep);
      expect_same(expected, got);
    }
}

TEST(ParticleStore, CompactIncreasingKeepsTheUntouchedPrefixAndSkipsEmptyArrays) {
  std::vector<int> a = {0, 1, 2, 3, 4, 5, 6};
  compact_increasing(a, {0, 1, 4, 6});
  EXPECT_EQ(a, (std::vector<int>{0, 1, 4, 6}));
  std::vector<double> unused;
  compact_increasing(unused, {0, 3});
  EXPECT_TRUE(unused.empty());
}

}  // namespace
}  // namespace boycott::particles
