// The velocity profile across the gap (coupling/velocity_profile.hpp) on particles whose band means
// are known: each band's mean velocities, the fluid velocity seen, the slip, the sample and flux
// shares, and the bands weighted by their sample shares giving the mean over all particles.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "coupling/velocity_profile.hpp"
#include "particles/particle_store.hpp"

using namespace boycott;

namespace {

std::vector<std::vector<double>> parse_rows(const std::string& csv) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::istringstream f(line);
    std::string cell;
    while (std::getline(f, cell, ',')) r.push_back(std::stod(cell));
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

TEST(VelocityProfile, BandMeansSlipAndSharesOfKnownParticles) {
  // A 6 mm gap in 3 bands of 2 mm: two particles in the first band, one in the last, none in the
  // middle; sampled twice (two steps), the second time with every velocity doubled.
  coupling::VelocityProfile prof(0.0, 0.006, 3);
  particles::ParticleStore s;
  s.add(0, 0.0, 0.0005, 0.0, 0.3e-3, 2650.0);
  s.add(1, 0.0, 0.0015, 0.0, 0.3e-3, 2650.0);
  s.add(2, 0.0, 0.0055, 0.0, 0.3e-3, 2650.0);
  const double vz[3] = {-0.10, -0.20, -0.40}, vy[3] = {0.01, -0.03, 0.0};
  const double wf[3] = {0.05, 0.03, -0.01}, vf[3] = {0.0, 0.01, 0.02};
  for (double scale : {1.0, 2.0}) {
    for (int i = 0; i < 3; ++i) {
      s.vz[i] = scale * vz[i], s.vy[i] = scale * vy[i];
      s.ufz[i] = scale * wf[i], s.ufy[i] = scale * vf[i];
    }
    prof.add(s);
  }
  const auto rows = parse_rows(prof.csv());
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& r : rows) ASSERT_EQ(r.size(), 9u);
  // Band 0: samples (-0.10, -0.20, -0.20, -0.40) -> w_p -0.225; w_f (0.05, 0.03, 0.10, 0.06) -> 0.06.
  const auto& b0 = rows[0];
  EXPECT_DOUBLE_EQ(b0[0], 0.001);
  EXPECT_NEAR(b0[1], 4.0 / 6.0, 1e-9);  // written to 9 digits
  EXPECT_NEAR(b0[2], -0.225, 1e-12);
  EXPECT_NEAR(b0[3], (1.0 + 2.0) * (0.01 - 0.03) / 4.0, 1e-12);  // (1 + 2) x the first step, 4 samples
  EXPECT_NEAR(b0[4], 0.06, 1e-12);
  EXPECT_NEAR(b0[5], (1.0 + 2.0) * 0.01 / 4.0, 1e-12);
  EXPECT_NEAR(b0[6], -0.225 - 0.06, 1e-12);
  EXPECT_NEAR(b0[7], b0[3] - b0[5], 1e-12);
  // The flux: band 0 carries 0.9 m/s of the 2.1 m/s summed over the samples, band 2 the rest.
  EXPECT_NEAR(b0[8], 0.9 / 2.1, 1e-9);
  // The empty band: no means, no shares.
  EXPECT_TRUE(std::isnan(rows[1][2]));
  EXPECT_EQ(rows[1][1], 0.0);
  EXPECT_EQ(rows[1][8], 0.0);
  const auto& b2 = rows[2];
  EXPECT_NEAR(b2[2], -0.6, 1e-12);
  EXPECT_NEAR(b2[6], -0.6 - (-0.015), 1e-12);
  EXPECT_NEAR(b2[8], 1.2 / 2.1, 1e-9);
  // The bands weighted by their sample shares give the mean over every sample: <<w_p>>.
  EXPECT_NEAR(b0[1] * b0[2] + b2[1] * b2[2], -2.1 / 6.0, 1e-9);
}
