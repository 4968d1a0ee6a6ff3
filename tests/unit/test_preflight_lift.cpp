// `case check` names the lift law's validity range when a case's settling Reynolds number Re_p
// leaves it (checks/preflight.cpp, check_lift_range): Saffman (1965) and McLaughlin (1991) are
// asymptotic theories for Re_p << 1 (warned from Re_p = 1), Mei's (1992) factor a fit over
// 0.1 <= Re_p <= 100 (Dandy & Dwyer 1990).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "checks/preflight.hpp"
#include "core/case_params.hpp"

namespace boycott {
namespace {

/// The pre-flight's warnings about the lift law, and its Re_p.
std::vector<std::string> lift_warnings(const CaseParams& p, double* re_p = nullptr) {
  const checks::Preflight pre = checks::preflight(p);
  std::vector<std::string> w;
  for (const auto& s : pre.warnings)
    if (s.find("forces.lift") != std::string::npos) w.push_back(s);
  for (const auto& it : pre.items)
    if (it.name == "Re_p" && re_p) *re_p = it.value;
  return w;
}

bool names(const std::vector<std::string>& w, const std::string& what) {
  return w.size() == 1 && w[0].find(what) != std::string::npos;
}

TEST(PreflightLift, TheBaseCaseIsInsideMeisFittedRange) {
  CaseParams p;  // Re_p 54, forces.lift = "saffman_mei"
  validate(p);
  double re = 0.0;
  EXPECT_TRUE(lift_warnings(p, &re).empty());
  EXPECT_NEAR(re, 54.0, 0.5);
  p.forces.lift = "none";
  EXPECT_TRUE(lift_warnings(p).empty());
}

TEST(PreflightLift, AsymptoticLawsAreNamedWithTheirRangeAtFiniteRe) {
  CaseParams p;
  p.forces.lift = "mclaughlin";
  validate(p);
  auto w = lift_warnings(p);
  EXPECT_TRUE(names(w, "McLaughlin's (1991) J(epsilon) holds for Re_p << 1 and Re_w << 1")) << w.size();
  EXPECT_TRUE(names(w, "saffman_mei is fitted up to Re_p = 100"));
  p.forces.lift = "saffman";
  w = lift_warnings(p);
  EXPECT_TRUE(names(w, "Saffman's (1965, 1968) lift holds for Re_p << Re_w^1/2 << 1")) << w.size();
  // Below Re_p = 1 neither is warned about: a viscous fluid, Re_p ~ 1e-3.
  p.fluid.viscosity_pa_s = 0.5;
  for (const char* law : {"mclaughlin", "saffman"}) {
    p.forces.lift = law;
    double re = 0.0;
    EXPECT_TRUE(lift_warnings(p, &re).empty()) << law;
    EXPECT_LT(re, 0.01);
  }
}

TEST(PreflightLift, MeisFactorIsNamedOutsideItsFittedRange) {
  CaseParams p;
  p.fluid.viscosity_pa_s = 0.5;  // Re_p ~ 1e-3
  validate(p);
  auto w = lift_warnings(p);
  EXPECT_TRUE(names(w, "a fit over 0.1 <= Re_p <= 100 and 0.005 <= Re_w / (2 Re_p) <= 0.4")) << w.size();
  EXPECT_TRUE(names(w, "below it mclaughlin (Re_p << 1, Re_w << 1) is the theory"));
  p.fluid.viscosity_pa_s = 0.3e-3;  // Re_p ~ 250
  double re = 0.0;
  w = lift_warnings(p, &re);
  EXPECT_GT(re, 100.0);
  EXPECT_TRUE(names(w, "a fit over 0.1 <= Re_p <= 100")) << w.size();
  p.forces.lift = "mclaughlin";
  EXPECT_TRUE(names(lift_warnings(p), "no lift law here covers Re_p > 100"));
  // Mei's fit with its jump bridged rests on the same fit, and is named with it.
  p.forces.lift = "saffman_mei_continuous";
  w = lift_warnings(p);
  EXPECT_TRUE(names(w, "forces.lift = \"saffman_mei_continuous\" at Re_p")) << w.size();
  EXPECT_TRUE(names(w, "a fit over 0.1 <= Re_p <= 100")) << w.size();
}

}  // namespace
}  // namespace boycott
