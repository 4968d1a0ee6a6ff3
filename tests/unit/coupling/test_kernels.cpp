// Void-fraction kernels: partition of unity, exact first moment (linear fields sampled exactly),
// wall folding that keeps every weight inside the channel.
#include <gtest/gtest.h>

#include <random>

#include "coupling/kernels.hpp"

using namespace boycott::coupling;

namespace {
constexpr KernelKind kKinds[] = {KernelKind::cell, KernelKind::trilinear, KernelKind::trilinear_smoothed};
}

TEST(Kernel, CellAndFaceWeightsSumToOne) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (KernelKind k : kKinds)
    for (bool walls : {false, true})
      for (int t = 0; t < 1000; ++t) {
        const double h = 1e-3;
        const int n = 6;
        const double x = walls ? (0.3e-3 + u(rng) * (n * h - 0.6e-3)) : u(rng) * n * h;
        const Weights1D c = cell_weights(k, x, h, n, walls);
        const Weights1D f = face_weights(c);
        double sc = 0.0, sf = 0.0;
        for (int m = 0; m < c.n; ++m) sc += c.w[m];
        for (int m = 0; m < f.n; ++m) sf += f.w[m];
        EXPECT_NEAR(sc, 1.0, 1e-14);
        EXPECT_NEAR(sf, 1.0, 1e-14);
        if (walls) {
          EXPECT_GE(c.first, 0);
          EXPECT_LE(c.first + c.n, n);
        }
      }
}

TEST(Kernel, SmoothKernelsSampleLinearFieldsExactly) {
  // Away from walls the weighted mean of the cell centres (and of the faces) is the particle
  // position: a linear field is read without error at cell centres and at faces alike.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 1e-3;
  for (KernelKind k : {KernelKind::trilinear, KernelKind::trilinear_smoothed})
    for (int t = 0; t < 1000; ++t) {
      const double x = (2.0 + 6.0 * u(rng)) * h;
      const Weights1D c = cell_weights(k, x, h, 10, false);
      const Weights1D f = face_weights(c);
      double mc = 0.0, mf = 0.0;
      for (int m = 0; m < c.n; ++m) mc += c.w[m] * (c.first + m + 0.5) * h;
      for (int m = 0; m < f.n; ++m) mf += f.w[m] * (f.first + m) * h;
      EXPECT_NEAR(mc, x, 1e-15);
      EXPECT_NEAR(mf, x, 1e-15);
    }
}

TEST(Kernel, SmoothedKernelSpreadsAParticleOverThreeCells) {
  // A particle at a cell centre keeps 3/4 of its volume there with trilinear_smoothed (1/8 to
  // each neighbour) against all of it with the trilinear kernel: the reason it is the default on
  // the paper's dx = 1.7 d grid.
  const Weights1D s = cell_weights(KernelKind::trilinear_smoothed, 2.5e-3, 1e-3, 10, false);
  ASSERT_EQ(s.n, 3);
  EXPECT_EQ(s.first, 1);
  EXPECT_NEAR(s.w[0], 0.125, 1e-15);
  EXPECT_NEAR(s.w[1], 0.75, 1e-15);
  EXPECT_NEAR(s.w[2], 0.125, 1e-15);
  const Weights1D t = cell_weights(KernelKind::trilinear, 2.5e-3, 1e-3, 10, false);
  EXPECT_EQ(t.first, 2);
  EXPECT_NEAR(t.w[0], 1.0, 1e-15);
  EXPECT_NEAR(t.w[1], 0.0, 1e-15);
}

TEST(Kernel, WallFoldingMirrorsTheOutsidePart) {
  // Particle 0.3 mm from the wall at y = 0, cell 1 mm: the smoothed kernel's share below the
  // wall (cell -1) is mirrored into cell 0.
  const Weights1D w = cell_weights(KernelKind::trilinear_smoothed, 0.3e-3, 1e-3, 6, true);
  EXPECT_EQ(w.first, 0);
  ASSERT_EQ(w.n, 2);
  const double dl = 0.3 - 0.5;  // offset from the centre of cell 0, in cells
  EXPECT_NEAR(w.w[0], 0.75 - dl * dl + 0.5 * (0.5 - dl) * (0.5 - dl), 1e-15);
  EXPECT_NEAR(w.w[1], 0.5 * (0.5 + dl) * (0.5 + dl), 1e-15);
}

TEST(Kernel, UnknownNameIsAnInputError) {
  EXPECT_THROW(kernel_from_name("gaussian"), boycott::InputError);
}
