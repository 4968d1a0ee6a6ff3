// Drag laws against the base case's terminal velocities (computed from the paper's Eqs. 12-15) and the
// Ergun equation that the dense branch of Eq. 13 encodes.
#include <gtest/gtest.h>

#include <cmath>

#include "core/constants.hpp"
#include "coupling/drag_laws.hpp"

using namespace boycott;
using namespace boycott::coupling;

namespace {
double vt(double d, double rho_p, double mu) {
  return terminal_slip_speed(DragDiFelicePaper{}, 1.0, d, rho_p, 1000.0, mu, 9.81);
}
}  // namespace

TEST(DragLaw, DiFeliceTerminalVelocitiesMatchDesignBrief) {
  // Design brief section 4, given to two significant figures: tolerance half a unit in the last
  // printed digit.
  EXPECT_NEAR(vt(0.6e-3, 2650.0, 1.0e-3), 0.090, 0.0005);
  EXPECT_NEAR(vt(0.6e-3, 2650.0, 1.0e-2), 0.026, 0.0005);
  EXPECT_NEAR(vt(0.4e-3, 2650.0, 1.0e-3), 0.059, 0.0005);
  EXPECT_NEAR(vt(0.6e-3, 1500.0, 1.0e-3), 0.040, 0.0005);
  // Re of the base case: 54 (brief).
  EXPECT_NEAR(1000.0 * vt(0.6e-3, 2650.0, 1.0e-3) * 0.6e-3 / 1.0e-3, 54.0, 0.5);
}

TEST(DragLaw, DenseBranchIsTheErgunEquationPerParticle) {
  // N particles per volume alpha_p / V_p, each with drag beta u_s, u_s = U / alpha_f, balance
  // alpha_f dP/dL: dP/dL = n beta u_s / alpha_f must equal Eq. 20 (150 vs 8.33 x 18 = 149.94 and
  // 1.75 vs 0.0972 x 18 = 1.7496: 0.04 % apart).
  const double d = 1e-3, rho = 1000.0, mu = 1e-3;
  for (double af : {0.36, 0.5, 0.7}) {
    for (double U : {1e-4, 1e-2, 0.5}) {
      const double us = U / af, ap = 1.0 - af, vp = kPi * d * d * d / 6.0;
      const double beta = DragDiFelicePaper{}.beta(af, us, d, rho, mu);
      const double dpdl = ap / vp * beta * us / af;
      const double ergun =
          150.0 * mu * ap * ap / (d * d * af * af * af) * U + 1.75 * rho * ap / (d * af * af * af) * U * U;
      EXPECT_NEAR(dpdl / ergun, 1.0, 4.5e-4) << "alpha_f " << af << " U " << U;
    }
  }
}

TEST(DragLaw, DiluteBranchTendsToStokesAtLowReynolds) {
  const double d = 0.6e-3, mu = 1e-3;
  const double beta = DragDiFelicePaper{}.beta(1.0, 1e-9, d, 1000.0, mu);
  EXPECT_NEAR(beta / (3.0 * kPi * mu * d), 1.0, 1e-5);
  // The voidage correction alpha_f^-zeta raises drag in a suspension: zeta -> 3.7 at low Re.
  const double b09 = DragDiFelicePaper{}.beta(0.9, 1e-9, d, 1000.0, mu);
  EXPECT_NEAR(b09 / beta,
              std::pow(0.9, -3.7 + 0.65 * std::exp(-0.5 * std::pow(1.5 + 9 - std::log10(0.6), 2))), 1e-6);
}

TEST(DragLaw, UnknownNameIsAnInputError) {
  EXPECT_THROW(visit_drag_law("beetstra2007", [](const auto&) { return 0.0; }), InputError);
}

TEST(DragLaw, DiFeliceOriginalFormMatchesHandValues) {
  // F = 1/2 C_d0 rho_f pi r^2 eps^(2 - chi) |s| s, C_d0 = (0.63 + 4.8 / Re_s^0.5)^2,
  // Re_s = rho_f d eps |s| / mu, chi = 3.7 - 0.65 exp(-(1.5 - log10 Re_s)^2 / 2); beta = F / s,
  // evaluated by hand (Python, double precision) for d = 0.6 mm in water.
  const double d = 0.6e-3, rho = 1000.0, mu = 1e-3;
  const DragDiFelice law;
  EXPECT_NEAR(law.beta(0.9, 0.05, d, rho, mu) / 1.906407969832e-05, 1.0, 1e-11);  // Re_s 27, chi 3.0515
  EXPECT_NEAR(law.beta(0.5, 0.01, d, rho, mu) / 4.068494177182e-05, 1.0, 1e-11);  // Re_s 3, chi 3.3148
  EXPECT_NEAR(law.beta(1.0, 0.09, d, rho, mu) / 2.095037236176e-05, 1.0, 1e-11);  // Re_s 54, C_d0 1.6466
  // Finite as Re_s -> 0: (4.8^2 / 8) pi mu d eps^(1 - chi), chi -> 3.7.
  EXPECT_NEAR(law.beta(0.8, 0.0, d, rho, mu) / (4.8 * 4.8 / 8.0 * kPi * mu * d * std::pow(0.8, 1.0 - 3.7)),
              1.0, 1e-12);
  // Isolated base-case sphere (rho_p 2650): 88.23 mm/s by hand (bisection in Python), against
  // 90 mm/s with the paper's printed law (Dallavalle's C_d0 against Schiller-Naumann's).
  EXPECT_NEAR(terminal_slip_speed(law, 1.0, d, 2650.0, rho, mu, 9.81), 0.0882330, 1e-6);
}
