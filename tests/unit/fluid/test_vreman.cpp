// Vreman (2004) subgrid viscosity against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/vreman.hpp"

namespace boycott::fluid {
namespace {

TEST(VremanViscosity, MatchesClosedFormForDiagonalGradient) {
  // grad = diag(a, b, 0), equal widths D: beta = D^2 diag(a^2, b^2, 0), B = D^4 a^2 b^2,
  // nu_t = c D^2 |a b| / sqrt(a^2 + b^2) = 0.07 * 1e-6 * 2 / sqrt(5) = 6.260990337e-8 m^2/s.
  const std::array<std::array<double, 3>, 3> g = {{{1.0, 0.0, 0.0}, {0.0, 2.0, 0.0}, {0.0, 0.0, 0.0}}};
  EXPECT_NEAR(vreman_viscosity(g, {1e-3, 1e-3, 1e-3}, 0.07), 6.260990337e-8, 1e-17);
}

TEST(VremanViscosity, MatchesHandValueForGeneralGradientAndAnisotropicCells) {
  // alpha_ij = d u_j / d x_i below, widths (1, 2, 0.5) mm: alpha:alpha = 7.41 1/s^2,
  // B_beta = 3.585495e-11 m^4/s^4 (worked out term by term), nu_t = 0.07 sqrt(B/7.41).
  const std::array<std::array<double, 3>, 3> g = {{{0.3, -1.2, 0.5}, {2.0, 0.1, -0.7}, {0.4, 0.9, -0.4}}};
  EXPECT_NEAR(vreman_viscosity(g, {1e-3, 2e-3, 0.5e-3}, 0.07), 1.5397970974e-7, 1e-16);
}

TEST(VremanViscosity, VanishesInPlaneShear) {
  // dw/dy only (plane Poiseuille): a rank-one gradient, B_beta = 0 (Vreman 2004, section 3).
  const std::array<std::array<double, 3>, 3> g = {{{0.0, 0.0, 0.0}, {0.0, 0.0, 37.0}, {0.0, 0.0, 0.0}}};
  EXPECT_EQ(vreman_viscosity(g, {1e-3, 1e-3, 1e-3}), 0.0);
  // any plane shear, e.g. u = s (n . x) t with n = (1,1,0)/sqrt2, t = (1,-1,0)/sqrt2: rank one
  const double s = 5.0;
  const std::array<std::array<double, 3>, 3> g2 = {
      {{0.5 * s, -0.5 * s, 0.0}, {0.5 * s, -0.5 * s, 0.0}, {0.0, 0.0, 0.0}}};
  EXPECT_EQ(vreman_viscosity(g2, {1e-3, 1e-3, 1e-3}), 0.0);
  EXPECT_EQ(vreman_viscosity({}, {1e-3, 1e-3, 1e-3}), 0.0);
}

}  // namespace
}  // namespace boycott::fluid
