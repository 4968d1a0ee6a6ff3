// The whole table of McLaughlin's J(epsilon) in coupling/lift_laws.hpp against its quadrature
// (mclaughlin_quadrature.hpp, to 1e-9): every node to the 1e-9 it is printed to, and every point
// halfway between two nodes to what the monotone cubic leaves (2.4e-4 at most, at the minimum of J
// near epsilon 0.17; below 4e-5 elsewhere, 0.002 % of J(inf)). Long (a few minutes): it is how the
// table is made; its output is the table in the header's form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "coupling/lift_laws.hpp"
#include "tests/unit/coupling/mclaughlin_quadrature.hpp"

namespace bc = boycott::coupling;
namespace mc = boycott::coupling::mclaughlin;

TEST(McLaughlinTable, EveryNodeIsTheQuadratureAndTheCubicHoldsBetweenThem) {
  const double j_inf = boycott::test::mclaughlin_j_by_quadrature(0.0, 1e-9);
  std::printf("inline constexpr double kJInfinity = %.9f;\n", j_inf);
  EXPECT_NEAR(mc::kJInfinity, j_inf, 2e-9);
  std::printf("inline constexpr std::array<double, %zu> kJ = {\n", mc::kJ.size());
  double worst_between = 0.0, worst_between_eps = 0.0;
  for (std::size_t k = 0; k < mc::kJ.size(); ++k) {
    const double x = mc::kLog10EpsilonFirst + mc::kLog10EpsilonStep * static_cast<double>(k);
    const double j = boycott::test::mclaughlin_j_by_quadrature(std::pow(10.0, x), 1e-9);
    std::printf("%s%.9f,%s", k % 6 == 0 ? "    " : " ", j, k % 6 == 5 || k + 1 == mc::kJ.size() ? "\n" : "");
    EXPECT_NEAR(mc::kJ[k], j, 2e-9) << "epsilon " << std::pow(10.0, x);
    if (k + 1 == mc::kJ.size()) break;
    const double e_mid = std::pow(10.0, x + 0.5 * mc::kLog10EpsilonStep);
    const double d =
        std::abs(bc::mclaughlin_j(e_mid) - boycott::test::mclaughlin_j_by_quadrature(e_mid, 1e-9));
    if (d > worst_between) worst_between = d, worst_between_eps = e_mid;
    EXPECT_LT(d, e_mid > 0.2 ? 5e-5 : 3e-4) << "epsilon " << e_mid;
  }
  std::printf("};\n");
  std::printf("largest interpolation error between nodes: %.3g at epsilon %.4g\n", worst_between,
              worst_between_eps);
}
