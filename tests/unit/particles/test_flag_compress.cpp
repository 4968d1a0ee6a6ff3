// compress_flagged (flag_compress.hpp) against the plain definition: the flagged positions, in
// order, on lengths that leave every remainder of the 8-wide groups, with sparse, dense, empty
// and full flag patterns.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "particles/flag_compress.hpp"

using boycott::particles::compress_flagged;

TEST(FlagCompress, AppendsTheFlaggedPositionsInOrderForEveryLengthAndDensity) {
  std::mt19937 rng(7);
  for (const double density : {0.0, 0.05, 0.5, 0.95, 1.0}) {
    std::bernoulli_distribution coin(density);
    for (std::size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 63, 64, 1000, 4099}) {
      std::vector<std::uint8_t> flag(n);
      std::vector<std::uint32_t> a(n), want_a, want_p;
      for (std::size_t p = 0; p < n; ++p) {
        flag[p] = coin(rng) ? 1 : 0;
        a[p] = static_cast<std::uint32_t>(rng());
        if (flag[p]) want_a.push_back(a[p]), want_p.push_back(static_cast<std::uint32_t>(p));
      }
      std::vector<std::uint32_t> out_a(n, 0xdeadbeef), out_p(n, 0xdeadbeef), only_p(n, 0xdeadbeef);
      const std::size_t k = compress_flagged(n, flag.data(), a.data(), out_a.data(), out_p.data());
      ASSERT_EQ(k, want_p.size()) << "n " << n << " density " << density;
      EXPECT_EQ(std::vector<std::uint32_t>(out_a.begin(), out_a.begin() + k), want_a);
      EXPECT_EQ(std::vector<std::uint32_t>(out_p.begin(), out_p.begin() + k), want_p);
      // without the values: the positions alone, the same count
      ASSERT_EQ(compress_flagged(n, flag.data(), nullptr, nullptr, only_p.data()), k);
      EXPECT_EQ(std::vector<std::uint32_t>(only_p.begin(), only_p.begin() + k), want_p);
    }
  }
}

TEST(FlagCompress, ReadsAnyNonZeroByteAsAFlag) {
  // The wall test stores comparisons (0 or 1); a flag is any non-zero byte in both forms.
  std::vector<std::uint8_t> flag(20, 0);
  flag[3] = 2, flag[9] = 255, flag[18] = 1;
  std::vector<std::uint32_t> out(20);
  ASSERT_EQ(compress_flagged(flag.size(), flag.data(), nullptr, nullptr, out.data()), 3u);
  EXPECT_EQ(out[0], 3u);
  EXPECT_EQ(out[1], 9u);
  EXPECT_EQ(out[2], 18u);
}
