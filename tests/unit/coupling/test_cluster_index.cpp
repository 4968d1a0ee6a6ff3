// The cluster index of the particles in the x-z plane (coupling/cluster_index.hpp,
// stats/dispersion.hpp) on arrangements whose value is known: centres placed at random give 1 on
// average with the scatter sqrt(2 (1 - 1/N) / (M - 1)) per sample, a lattice of one particle per
// column gives 0, clumps of m particles placed at random give m.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "coupling/cluster_index.hpp"
#include "particles/particle_store.hpp"
#include "stats/dispersion.hpp"

using namespace boycott;

namespace {

// The smoke case's box and grid: 20 x 20 columns of 1 mm, a 6 mm gap of 6 cells, 2 400 particles
// (its 11.3 % solid fraction of 0.6 mm spheres): 6 per column.
GridSpec smoke_grid() {
  GridSpec g;
  g.n = {20, 6, 20};
  g.length_m = {0.02, 0.006, 0.02};
  return g;
}
constexpr std::array<double, 3> kLo = {0.0, 0.0, 0.0};
constexpr int kParticles = 2400;
constexpr double kRadius = 0.3e-3;

/// N clumps of m particles, each clump's particles at one centre drawn uniformly in the box (y too).
particles::ParticleStore random_clumps(const GridSpec& g, int clumps, int m, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  particles::ParticleStore s;
  for (int c = 0; c < clumps; ++c) {
    const double x = u(rng) * g.length_m[0], z = u(rng) * g.length_m[2];
    for (int k = 0; k < m; ++k) s.add(c * m + k, x, u(rng) * g.length_m[1], z, kRadius, 2650.0);
  }
  return s;
}

struct Moments {
  double mean = 0.0, sd = 0.0;
};

/// The index's mean and standard deviation over `samples` arrangements of clumps of m.
Moments index_over_arrangements(int m, int samples, unsigned seed) {
  const GridSpec g = smoke_grid();
  std::mt19937_64 rng(seed);
  std::vector<double> v;
  for (int r = 0; r < samples; ++r)
    v.push_back(stats::dispersion_index(
        coupling::xz_column_counts(random_clumps(g, kParticles / m, m, rng), g, kLo)));
  Moments mo;
  for (double x : v) mo.mean += x / samples;
  for (double x : v) mo.sd += (x - mo.mean) * (x - mo.mean) / (samples - 1);
  mo.sd = std::sqrt(mo.sd);
  return mo;
}

}  // namespace

TEST(ClusterIndex, RandomCentresGiveOneWithTheBinomialScatter) {
  // 400 arrangements: the mean's standard error is sd / 20 = 0.0035; the sample sd's relative
  // error about 1 / sqrt(2 * 399) = 3.5 % (a little more: the index's tail is that of chi^2).
  // Both are held to 4 of their standard errors (the sd's: 15 %).
  const int samples = 400;
  const double sd = stats::dispersion_index_random_sd(kParticles, 400);
  const Moments mo = index_over_arrangements(1, samples, 11);
  std::printf("random: mean %.4f (expected 1 +- %.4f), sd %.4f (expected %.4f)\n", mo.mean,
              sd / std::sqrt(samples), mo.sd, sd);
  EXPECT_NEAR(mo.mean, 1.0, 4.0 * sd / std::sqrt(samples));
  EXPECT_NEAR(mo.sd / sd, 1.0, 0.15);
}

TEST(ClusterIndex, ClumpsOfFourGiveFour) {
  // The counts are 4 times those of 600 points in 400 columns: the index is 4 X^2 / (M - 1), of
  // mean 4 and sd 4 sqrt(2 (1 - 1/600) / 399) = 0.283 per sample; over 100 arrangements the mean
  // is held to 4 standard errors (0.113).
  const int samples = 100;
  const double sd = 4.0 * stats::dispersion_index_random_sd(kParticles / 4, 400);
  const Moments mo = index_over_arrangements(4, samples, 12);
  std::printf("clumps of 4: mean %.4f (expected 4 +- %.4f)\n", mo.mean, sd / std::sqrt(samples));
  EXPECT_NEAR(mo.mean, 4.0, 4.0 * sd / std::sqrt(samples));
}

TEST(ClusterIndex, ALatticeOfOnePerColumnGivesZero) {
  // One particle in every column, at random y and anywhere inside its column, some of them moved
  // by a period in x or z (a periodic position not yet wrapped into the box is counted where it
  // belongs).
  const GridSpec g = smoke_grid();
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  particles::ParticleStore s;
  const double hx = g.dx(0), hz = g.dx(2);
  for (int k = 0; k < g.n[2]; ++k)
    for (int i = 0; i < g.n[0]; ++i) {
      const double shift_x = (i % 3 == 0 ? g.length_m[0] : 0.0) - (i % 5 == 0 ? g.length_m[0] : 0.0);
      const double shift_z = k % 4 == 0 ? -g.length_m[2] : 0.0;
      s.add(i + g.n[0] * k, (i + 0.05 + 0.9 * u(rng)) * hx + shift_x, u(rng) * g.length_m[1],
            (k + 0.05 + 0.9 * u(rng)) * hz + shift_z, kRadius, 2650.0);
    }
  const auto counts = coupling::xz_column_counts(s, g, kLo);
  for (const auto c : counts) EXPECT_EQ(c, 1);
  EXPECT_EQ(stats::dispersion_index(counts), 0.0);
}

TEST(ClusterIndex, SmallCasesByHand) {
  // Two cells: N = 4 as (4, 0) gives S = 4, N p (1 - p) = 1, I = 4; (3, 1) gives I = 1; (2, 2) 0.
  EXPECT_DOUBLE_EQ(stats::dispersion_index({4, 0}), 4.0);
  EXPECT_DOUBLE_EQ(stats::dispersion_index({3, 1}), 1.0);
  EXPECT_DOUBLE_EQ(stats::dispersion_index({2, 2}), 0.0);
  // All N in one of M cells, the most clustered: S = N^2 (M - 1) / M^2, I = N.
  EXPECT_DOUBLE_EQ(stats::dispersion_index({0, 0, 9, 0, 0}), 9.0);
  EXPECT_TRUE(std::isnan(stats::dispersion_index({0, 0, 0})));
  EXPECT_TRUE(std::isnan(stats::dispersion_index({7})));
}
