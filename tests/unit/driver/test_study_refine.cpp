// A study's [refine] table (driver/study/refine.hpp): what it accepts and refuses, the curves it
// refines, the case of an added point; and the refusal of a study too large to hold.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "driver/study/refine.hpp"
#include "driver/study/study.hpp"

namespace bd = boycott::driver;

namespace {

// Two groups, one with two viscosities; time.end zipped with the angle.
const char* kRefined = R"(
name = "r"
base = { scene = "inclined_settling", time = { end = 2.0, average_from = 1.0 } }
zip = { "gravity.angle_deg" = [30, 60, 90], "time.end" = [2.0, 3.0, 2.0] }
[[group]]
name = "base"
[[group]]
name = "visc"
matrix = { "fluid.viscosity" = [2.0e-3, 3.0e-3] }
[refine]
key = "gravity.angle_deg"
objective = "max_r_acc"
resolution = 2.5
max_points = 3
set = { "time.end" = 4.0 }
)";

/// The refusal's message; the test fails where the study is accepted.
std::string refusal(const std::string& text) {
  std::string why;
  EXPECT_THROW(
      try { bd::expand_study_string(text); } catch (const boycott::InputError& e) {
        why = e.what();
        throw;
      },
      boycott::InputError);
  return why;
}

std::string with(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

}  // namespace

TEST(StudyRefine, ReadsTheTableAndFindsOneCurvePerGroupSetting) {
  const auto s = bd::expand_study_string(kRefined);
  ASSERT_TRUE(s.refine);
  EXPECT_EQ(s.refine->key, "gravity.angle_deg");
  EXPECT_EQ(s.refine->objective, "max_r_acc");
  EXPECT_EQ(s.refine->resolution, 2.5);
  EXPECT_EQ(s.refine->max_points, 3);
  ASSERT_EQ(s.refine->set.size(), 1u);
  const auto curves = bd::refine_series(s);
  // base: one curve; visc: one per viscosity (time.end is zipped with the angle, no curve of its own).
  ASSERT_EQ(curves.size(), 3u);
  EXPECT_EQ(curves[0].group, "base");
  EXPECT_EQ(curves[0].setting, "");
  EXPECT_EQ(curves[0].cases.size(), 3u);
  EXPECT_EQ(curves[1].setting, "fluid.viscosity=0.002");
  EXPECT_EQ(curves[2].setting, "fluid.viscosity=0.003");
  EXPECT_EQ(curves[2].cases.size(), 3u);
}

TEST(StudyRefine, AnAddedPointIsTheCurvesCaseAtTheNewAngleWithRefinesSet) {
  auto s = bd::expand_study_string(kRefined);
  const auto curves = bd::refine_series(s);
  const bd::StudyCase c = bd::refined_case(s, curves[2], 67.25, 0);
  EXPECT_EQ(c.group, "visc");
  EXPECT_EQ(c.refine_round, 0);
  EXPECT_EQ(c.params.gravity.angle_deg, 67.25);
  EXPECT_EQ(c.params.time.end_s, 4.0);
  EXPECT_EQ(c.params.fluid.viscosity_pa_s, 3.0e-3);
  EXPECT_EQ(c.point_id, c.id);
  // A case of its own, with the swept values of its curve and its own angle and end.
  for (const auto& other : s.cases) EXPECT_NE(other.id, c.id);
  const auto value = [&](const std::string& key) {
    for (const auto& [k, v] : c.swept)
      if (k == key) return v;
    return std::string("?");
  };
  EXPECT_EQ(value("gravity.angle_deg"), "67.25");
  EXPECT_EQ(value("time.end"), "4");
  EXPECT_EQ(value("fluid.viscosity"), s.cases[6].swept[0].second);
  // The same point made again is the same case; the study joins it to its curve.
  EXPECT_EQ(bd::refined_case(s, curves[2], 67.25, 0).id, c.id);
  s.cases.push_back(c);
  const auto again = bd::refine_series(s);
  EXPECT_EQ(again[2].cases.size(), 4u);
  EXPECT_EQ(again[1].cases.size(), 3u);
  EXPECT_EQ(bd::refined_value(67.2493, 2.5), 67.25);
}

TEST(StudyRefine, RefusesWhatItCannotRefineNamingWhy) {
  EXPECT_NE(refusal(with(kRefined, "max_points = 3", "max_points = 3\nstep = 1")).find("unknown key 'step'"),
            std::string::npos);
  EXPECT_NE(refusal(with(kRefined, "key = \"gravity.angle_deg\"", "key = \"fluid.viscosity\""))
                .find("refine finds the peak of a curve over the angle"),
            std::string::npos);
  EXPECT_NE(refusal(with(kRefined, "set = { \"time.end\" = 4.0 }", ""))
                .find("'time.end' is zipped with 'gravity.angle_deg'"),
            std::string::npos);
  EXPECT_NE(
      refusal(with(kRefined, "\"gravity.angle_deg\" = [30, 60, 90]", "\"gravity.angle_deg\" = [30, 60, 80]"))
          .find("needs a 90 deg point"),
      std::string::npos);
  EXPECT_NE(refusal(with(kRefined, "resolution = 2.5", "resolution = 0")).find("resolution = 0 must be"),
            std::string::npos);
  EXPECT_NE(refusal(with(kRefined, "resolution = 2.5", "")).find("resolution = (none) must be"),
            std::string::npos);
  EXPECT_NE(refusal(with(kRefined, "max_points = 3", "max_points = 0"))
                .find("max_points = 0 must be a whole number in [1, 50]"),
            std::string::npos);
  EXPECT_NE(
      refusal(with(kRefined, "objective = \"max_r_acc\"", "objective = \"min\"")).find("max_abs_settling"),
      std::string::npos);
}

namespace {

// Two groups whose zips differ: "ga" also zips the packed-bed step limit with the angle (on at the
// inclined angles, off at 90), as the paper's Ga 145.6 group does in studies/paper_base_full.toml.
const char* kGroupSets = R"(
name = "g"
base = { scene = "inclined_settling", time = { end = 2.0, average_from = 1.0 }, numerics = { drag_dt_limit = false } }
[[group]]
name = "base"
zip = { "gravity.angle_deg" = [30, 60, 90], "time.end" = [2.0, 3.0, 2.0] }
[[group]]
name = "ga"
set = { "fluid.viscosity" = 1.0e-2 }
zip = { "gravity.angle_deg" = [30, 60, 90], "time.end" = [2.0, 3.0, 2.0], "numerics.drag_dt_limit" = [true, true, false] }
refine_set = { "numerics.drag_dt_limit" = true, "time.end" = 5.0 }
[refine]
key = "gravity.angle_deg"
resolution = 2.5
set = { "time.end" = 4.0 }
)";

}  // namespace

// A group's refine_set gives its added points its own values of the keys zipped with the angle
// (over [refine] set's); another group's added points keep [refine] set's and their own base.
TEST(StudyRefine, AGroupsRefineSetGivesItsAddedPointsItsOwnValues) {
  const auto s = bd::expand_study_string(kGroupSets);
  const auto curves = bd::refine_series(s);
  ASSERT_EQ(curves.size(), 2u);
  EXPECT_EQ(curves[1].setting, "");  // the zipped limit splits no curve
  const bd::StudyCase ga = bd::refined_case(s, curves[1], 70.0, 0);
  EXPECT_EQ(ga.group, "ga");
  EXPECT_TRUE(ga.params.numerics.drag_dt_limit);
  EXPECT_EQ(ga.params.time.end_s, 5.0);
  EXPECT_EQ(ga.params.fluid.viscosity_pa_s, 1.0e-2);
  const bd::StudyCase base = bd::refined_case(s, curves[0], 70.0, 0);
  EXPECT_FALSE(base.params.numerics.drag_dt_limit);
  EXPECT_EQ(base.params.time.end_s, 4.0);
  EXPECT_NE(ga.id, base.id);
  // Without it, the zipped limit has no value for an added angle: refused, naming the group.
  const std::string without = with(kGroupSets, "\"numerics.drag_dt_limit\" = true, ", "");
  EXPECT_NE(refusal(without).find("'numerics.drag_dt_limit' is zipped with 'gravity.angle_deg' (group 'ga')"),
            std::string::npos)
      << refusal(without);
  EXPECT_NE(refusal(with(kGroupSets, "\"time.end\" = 5.0", "\"time.ends\" = 5.0"))
                .find("group 'ga': refine_set: unknown key 'time.ends'"),
            std::string::npos);
  // A study without [refine] adds no point for it to act on.
  const std::string no_refine = kGroupSets;
  EXPECT_NE(
      refusal(no_refine.substr(0, no_refine.find("[refine]")))
          .find("group 'ga': refine_set gives values to points [refine] adds; the study has no [refine]"),
      std::string::npos);
}

// A study of more cases than a study may hold is refused before any case is made: one sentence
// with the count and the limit (the large-study figures: docs/performance.md).
TEST(StudySize, AStudyAboveTheLimitIsRefusedNamingItsCountAndTheLimit) {
  const std::string big = R"(
name = "big"
[base]
scene = "inclined_settling"
[matrix]
"gravity.angle_deg" = [10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32,
  33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60,
  61, 62, 63, 64, 65, 66, 67, 68, 69, 70, 71, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 83, 84, 85, 86, 87, 88,
  89, 90]
"fluid.viscosity" = [1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 7e-3, 8e-3, 9e-3, 1e-2]
"particles.density" = [1500, 1600, 1700, 1800, 1900, 2000, 2100, 2200, 2300, 2400, 2500, 2600, 2650]
"particles.diameter" = [4e-4, 4.5e-4, 5e-4, 5.5e-4, 6e-4, 6.5e-4, 7e-4, 7.5e-4, 8e-4, 8.5e-4]
"seed" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]
)";
  const std::string e = refusal(big);
  EXPECT_NE(e.find("study 'big' expands to 1053000 cases, more than the 100000 a study may hold"),
            std::string::npos)
      << e;
  EXPECT_EQ(std::count(e.begin(), e.end(), '.'), 0) << "one sentence: " << e;
}
