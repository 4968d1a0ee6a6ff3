// The lift laws (coupling/lift_laws.hpp) against their published formulas, evaluated here from
// the exact shear and slip: Saffman (1965/1968) as the paper's Eq. 16, Mei's (1992, eq. 8)
// finite-Re ratio with its limits, and McLaughlin's (1991) J(epsilon) / J(inf) as a force (J
// itself: test_mclaughlin_lift.cpp).
#include <gtest/gtest.h>

#include <cmath>

#include "coupling/lift_laws.hpp"

namespace bc = boycott::coupling;

namespace {
constexpr double kRho = 1000.0, kNu = 1.0e-6, kD = 0.6e-3;

/// Eq. 16 written out for a slip along z and a vorticity along x (the settling channel's case:
/// s = (0, 0, s_z), w = (dw/dy, 0, 0)): F_y = 1.61 rho d^2 sqrt(nu/|w|) s_z w_x.
double saffman_fy(double s_z, double w_x) {
  return 1.61 * kRho * kD * kD * std::sqrt(kNu / std::abs(w_x)) * s_z * w_x;
}
}  // namespace

TEST(LiftLaws, SaffmanIsEquation16ForTheChannelsShearAndSlip) {
  for (double s_z : {-0.05, 0.01, 0.08})
    for (double w_x : {-300.0, -1.0, 20.0, 500.0}) {
      const double s[3] = {0.0, 0.0, s_z}, w[3] = {w_x, 0.0, 0.0};
      double f[3];
      bc::lift_force(bc::LiftLaw::saffman, s, w, kD, kRho, kNu, f);
      EXPECT_NEAR(f[1], saffman_fy(s_z, w_x), 1e-14 * std::abs(saffman_fy(s_z, w_x)));
      EXPECT_EQ(f[0], 0.0);
      EXPECT_EQ(f[2], 0.0);
    }
  // A settling particle (s_z > 0: the fluid rises past it) where the fluid's velocity grows with
  // y (w_x = dw/dy > 0) is pushed toward +y: toward the faster upward flow.
  const double s[3] = {0.0, 0.0, 0.05}, w[3] = {100.0, 0.0, 0.0};
  double f[3];
  bc::lift_force(bc::LiftLaw::saffman, s, w, kD, kRho, kNu, f);
  EXPECT_GT(f[1], 0.0);
}

TEST(LiftLaws, MeiFactorIsItsPublishedFormula) {
  // Mei (1992) eq. (8), beta = Re_w / (2 Re_p), written out for a few points.
  struct Point {
    double re_p, re_w, f;
  } pts[] = {
      {1.0, 0.2, (1.0 - 0.3314 * std::sqrt(0.1)) * std::exp(-0.1) + 0.3314 * std::sqrt(0.1)},
      {10.0, 2.0, (1.0 - 0.3314 * std::sqrt(0.1)) * std::exp(-1.0) + 0.3314 * std::sqrt(0.1)},
      {40.0, 16.0, (1.0 - 0.3314 * std::sqrt(0.2)) * std::exp(-4.0) + 0.3314 * std::sqrt(0.2)},
      {50.0, 40.0, 0.0524 * std::sqrt(0.4 * 50.0)},
      {100.0, 1.0, 0.0524 * std::sqrt(0.005 * 100.0)},
  };
  for (const auto& p : pts) EXPECT_NEAR(bc::mei_lift_factor(p.re_p, p.re_w), p.f, 1e-15) << p.re_p;
}

TEST(LiftLaws, MeiFactorTendsToSaffmanAtLowReAndFallsAtTheSuspensionsRe) {
  // Re_p -> 0 at fixed beta: Saffman's limit, f -> 1 (within the 0.3314 beta^1/2 Re_p / 10 it
  // still differs by).
  EXPECT_NEAR(bc::mei_lift_factor(1e-4, 2e-5), 1.0, 1e-4);
  // The two branches meet at Re_p = 40 up to (1 - alpha) e^-4 (Mei's fit is not continuous; and
  // 0.0524 sqrt(40) = 0.33141 against 0.3314: 1e-5 beta^1/2 more).
  for (double beta : {0.005, 0.05, 0.4}) {
    const double below = bc::mei_lift_factor(40.0, 2.0 * beta * 40.0);
    const double above = bc::mei_lift_factor(40.0 + 1e-9, 2.0 * beta * (40.0 + 1e-9));
    EXPECT_NEAR(below - above, (1.0 - 0.3314 * std::sqrt(beta)) * std::exp(-4.0), 1e-5) << beta;
  }
  // A proppant particle settling at Re_p ~ 30-50 in shear Re_w ~ 2-10 keeps 0.05-0.2 of Saffman's.
  for (double re_p : {30.0, 40.0, 50.0})
    for (double re_w : {2.0, 10.0}) {
      const double f = bc::mei_lift_factor(re_p, re_w);
      EXPECT_GT(f, 0.05) << re_p << " " << re_w;
      EXPECT_LT(f, 0.35) << re_p << " " << re_w;
    }
}

TEST(LiftLaws, SaffmanMeiIsSaffmanTimesTheFactorAndNoneIsZero) {
  const double s[3] = {0.002, -0.001, 0.04}, w[3] = {150.0, -20.0, 5.0};
  double fs[3], fm[3], fn[3];
  bc::lift_force(bc::LiftLaw::saffman, s, w, kD, kRho, kNu, fs);
  bc::lift_force(bc::LiftLaw::saffman_mei, s, w, kD, kRho, kNu, fm);
  bc::lift_force(bc::LiftLaw::none, s, w, kD, kRho, kNu, fn);
  const double sn = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  const double wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  const double f = bc::mei_lift_factor(sn * kD / kNu, wn * kD * kD / kNu);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fm[c], f * fs[c], 1e-14 * std::abs(fs[c])) << c;
    EXPECT_EQ(fn[c], 0.0);
  }
  // No vorticity or no slip: no lift (and no division by zero).
  const double zero[3] = {0.0, 0.0, 0.0};
  bc::lift_force(bc::LiftLaw::saffman_mei, s, zero, kD, kRho, kNu, fm);
  for (double v : fm) EXPECT_EQ(v, 0.0);
  bc::lift_force(bc::LiftLaw::saffman_mei, zero, w, kD, kRho, kNu, fm);
  for (double v : fm) EXPECT_EQ(v, 0.0);
}

TEST(LiftLaws, MeiContinuousBridgesTheJumpAndIsMeiOutsideTheBridge) {
  for (double beta : {0.005, 0.05, 0.13, 0.4}) {
    const auto re_w = [beta](double re_p) { return 2.0 * beta * re_p; };
    // Up to Re_p = 40 it is Mei's low branch, bit for bit.
    for (double re_p : {0.5, 10.0, 39.9, 40.0})
      EXPECT_EQ(bc::mei_continuous_lift_factor(re_p, re_w(re_p)), bc::mei_lift_factor(re_p, re_w(re_p)));
    // No jump at 40 (Mei's is (1 - 0.3314 beta^1/2) e^-4, ~0.015-0.018): across 1e-9 in Re_p the
    // factor moves by no more than its slope, |d f / d Re_p| < 0.01, allows.
    const double below = bc::mei_continuous_lift_factor(40.0, re_w(40.0));
    const double above = bc::mei_continuous_lift_factor(40.0 + 1e-9, re_w(40.0 + 1e-9));
    EXPECT_NEAR(below, above, 1e-10) << beta;
    // Continuous everywhere on 30-70 (steps of 1e-4 in Re_p move it by < 1e-5), never below
    // Mei's, and Mei's again from where the high branch crosses the low one (44-55 over this
    // beta range) on.
    double prev = bc::mei_continuous_lift_factor(30.0, re_w(30.0)), last_above = 0.0;
    for (double re_p = 30.0001; re_p < 70.0; re_p += 1e-4) {
      const double f = bc::mei_continuous_lift_factor(re_p, re_w(re_p)),
                   m = bc::mei_lift_factor(re_p, re_w(re_p));
      ASSERT_LT(std::abs(f - prev), 1e-5) << beta << " " << re_p;
      ASSERT_GE(f, m) << beta << " " << re_p;
      if (f > m) last_above = re_p;
      prev = f;
    }
    EXPECT_GT(last_above, 43.0) << beta;
    EXPECT_LT(last_above, 56.0) << beta;
  }
  // The suspension's beta 0.13: the bridge ends at Re_p 46.09 (bisection of low = high by hand).
  const double beta = 0.13, a = 0.3314 * std::sqrt(beta);
  const auto gap = [&](double r) {
    return (1.0 - a) * std::exp(-0.1 * r) + a - 0.0524 * std::sqrt(beta * r);
  };
  EXPECT_GT(gap(46.0), 0.0);
  EXPECT_LT(gap(46.2), 0.0);
  EXPECT_GT(bc::mei_continuous_lift_factor(46.0, 2.0 * beta * 46.0),
            bc::mei_lift_factor(46.0, 2.0 * beta * 46.0));
  EXPECT_EQ(bc::mei_continuous_lift_factor(46.2, 2.0 * beta * 46.2),
            bc::mei_lift_factor(46.2, 2.0 * beta * 46.2));
}

TEST(LiftLaws, SaffmanMeiContinuousIsSaffmanTimesItsFactor) {
  // The channel's case at Re_p = 42 (inside the bridge) and 30 (below it).
  const double w_x = 150.0;
  for (double re_p : {30.0, 42.0}) {
    const double s_z = re_p * kNu / kD;
    const double s[3] = {0.0, 0.0, s_z}, w[3] = {w_x, 0.0, 0.0};
    double fs[3], fc[3];
    bc::lift_force(bc::LiftLaw::saffman, s, w, kD, kRho, kNu, fs);
    bc::lift_force(bc::LiftLaw::saffman_mei_continuous, s, w, kD, kRho, kNu, fc);
    const double f = bc::mei_continuous_lift_factor(re_p, w_x * kD * kD / kNu);
    EXPECT_NEAR(fc[1], f * fs[1], 1e-12 * std::abs(fs[1])) << re_p;
    EXPECT_EQ(fc[0], 0.0);
    EXPECT_EQ(fc[2], 0.0);
  }
}

TEST(LiftLaws, McLaughlinIsSaffmanTimesJOverJInfinityAndReversesWhereJIsNegative) {
  // The channel's case (slip along z, vorticity along x) at three epsilon = (|w| nu)^1/2 / |s|:
  // 2 (J/J(inf) = 0.929), 0.5 (0.326) and 0.1 (J < 0: the lift points the other way).
  const double w_x = 100.0;
  for (double eps : {2.0, 0.5, 0.1}) {
    const double s_z = std::sqrt(w_x * kNu) / eps;
    const double s[3] = {0.0, 0.0, s_z}, w[3] = {w_x, 0.0, 0.0};
    double fs[3], fm[3];
    bc::lift_force(bc::LiftLaw::saffman, s, w, kD, kRho, kNu, fs);
    bc::lift_force(bc::LiftLaw::mclaughlin, s, w, kD, kRho, kNu, fm);
    const double ratio = bc::mclaughlin_j(eps) / bc::mclaughlin::kJInfinity;
    EXPECT_NEAR(fm[1], ratio * fs[1], 1e-12 * std::abs(fs[1])) << eps;
    EXPECT_EQ(fm[0], 0.0);
    EXPECT_EQ(fm[2], 0.0);
    EXPECT_EQ(fm[1] * fs[1] < 0.0, eps < 0.2) << eps;
  }
  // No vorticity or no slip: no lift (and no division by zero).
  const double s[3] = {0.0, 0.0, 0.01}, w[3] = {w_x, 0.0, 0.0}, zero[3] = {0.0, 0.0, 0.0};
  double f[3];
  bc::lift_force(bc::LiftLaw::mclaughlin, s, zero, kD, kRho, kNu, f);
  for (double v : f) EXPECT_EQ(v, 0.0);
  bc::lift_force(bc::LiftLaw::mclaughlin, zero, w, kD, kRho, kNu, f);
  for (double v : f) EXPECT_EQ(v, 0.0);
}
