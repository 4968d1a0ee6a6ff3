#include <gtest/gtest.h>

#include "core/case_params.hpp"
#include "core/error.hpp"

using namespace boycott;

TEST(CaseParams, DefaultsAreTableIII) {
  CaseParams p;
  validate(p);
  EXPECT_EQ(p.particles.count, 120000);
  // alpha_p = 0.113 for the base case (Table III).
  EXPECT_NEAR(p.solid_fraction(), 0.113, 0.0005);
  // m = 3.0e-7 kg; spring limit (pi/5) sqrt(m/k_n) = 184 us for k_n = 3.5 N/m.
  EXPECT_NEAR(p.particle_mass_kg(), 2.997e-7, 1e-10);
  EXPECT_NEAR(p.dem_spring_limit_s(), 184.0e-6, 1.0e-6);
  EXPECT_EQ(p.dem_substeps(), 50);
}

TEST(CaseParams, GravityIsInclinedInTheYZPlane) {
  CaseParams p;
  p.gravity.angle_deg = 90.0;
  auto g = p.gravity_vector();
  EXPECT_EQ(g[1], 0.0);
  EXPECT_DOUBLE_EQ(g[2], -9.81);
  p.gravity.angle_deg = 0.0;
  g = p.gravity_vector();
  EXPECT_DOUBLE_EQ(g[1], -9.81);
  EXPECT_EQ(g[2], 0.0);
}

TEST(CaseParams, ParsesTomlAndRejectsUnknownKeys) {
  auto p =
      parse_case_string("scene = \"dem_only\"\n[fluid]\nviscosity = 1e-2\n[domain]\ncells = [10, 6, 20]\n");
  EXPECT_EQ(p.scene, "dem_only");
  EXPECT_DOUBLE_EQ(p.fluid.viscosity_pa_s, 1e-2);
  EXPECT_EQ(p.domain.cells[2], 20);
  try {
    parse_case_string("[fluid]\nviscosityy = 1e-2\n");
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fluid.viscosityy"), std::string::npos);
  }
  EXPECT_THROW(parse_case_string("[fluid\nviscosity = 1"), InputError);
  EXPECT_THROW(parse_case_string("[fluid]\nviscosity = \"thick\""), InputError);
}

TEST(CaseParams, ValidationNamesFieldValueAndLimit) {
  auto expect_message = [](CaseParams p, const std::string& needle) {
    try {
      validate(p);
      FAIL() << "accepted, expected: " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  CaseParams p;
  p.fluid.viscosity_pa_s = -1e-3;
  expect_message(p, "fluid.viscosity = -0.001");
  p = CaseParams{};
  p.particles.diameter_m = 0.006;
  expect_message(p, "does not fit the channel");
  p = CaseParams{};
  p.contact.stiffness_n_m = 500.0;
  expect_message(p, "exceeds the spring limit");
  p = CaseParams{};
  p.particles.count = 10000000;
  expect_message(p, "overfills the box");
}

TEST(CaseParams, IdIsStableAndDistinguishesParameters) {
  CaseParams a, b;
  validate(a);
  validate(b);
  EXPECT_EQ(case_id(a), case_id(b));
  b.gravity.angle_deg = 70.0;
  EXPECT_NE(case_id(a), case_id(b));
  // The same case given by volume fraction instead of count has the same identity.
  CaseParams c;
  c.particles.volume_fraction = a.solid_fraction();
  validate(c);
  EXPECT_EQ(case_id(a), case_id(c));
  // JSON round trip keeps the identity.
  EXPECT_EQ(case_id(case_from_json(to_json(a))), case_id(a));
}

TEST(CaseParams, KeysAddedLaterKeepEveryExistingIdAtTheirDefaults) {
  // 34c0cdaa3b877dc1 is the id 30c36a8 (before numerics.pressure_velocity_coupling and
  // numerics.piso_correctors existed) gave the default case: study databases written then must
  // find their cases again.
  CaseParams a;
  validate(a);
  EXPECT_EQ(case_id(a), "34c0cdaa3b877dc1");
  CaseParams b = a;
  apply_override(b, "numerics.piso_correctors=2");  // the default, written out
  EXPECT_EQ(case_id(b), case_id(a));
  apply_override(b, "numerics.pressure_velocity_coupling=\"piso\"");
  EXPECT_NE(case_id(b), case_id(a));
  CaseParams c = b;
  apply_override(c, "numerics.piso_correctors=3");
  EXPECT_NE(case_id(c), case_id(b));
}

TEST(CaseParams, ASceneOnlyKeyIsHashedForItsSceneOnly) {
  // sediment.initial_flow came later and only sediment_transport reads it: the other scenes'
  // ids stay as they were, and a sediment case started from rest is another case.
  CaseParams a;
  validate(a);
  const std::string before = case_id(a);
  apply_override(a, "sediment.initial_flow=\"rest\"");
  EXPECT_EQ(case_id(a), before);
  CaseParams s;
  apply_override(s, "scene=\"sediment_transport\"");
  CaseParams r = s;
  apply_override(r, "sediment.initial_flow=\"rest\"");
  EXPECT_NE(case_id(r), case_id(s));
  apply_override(r, "sediment.initial_flow=\"laminar\"");
  EXPECT_THROW(validate(r), InputError);
}

TEST(CaseParams, OverridesUseTomlSyntax) {
  CaseParams p;
  apply_override(p, "gravity.angle_deg=75");
  apply_override(p, "scene=dem_only");
  apply_override(p, "domain.cells=[20,6,10]");
  EXPECT_DOUBLE_EQ(p.gravity.angle_deg, 75.0);
  EXPECT_EQ(p.scene, "dem_only");
  EXPECT_EQ(p.domain.cells[0], 20);
  EXPECT_THROW(apply_override(p, "nope.key=1"), InputError);
}
