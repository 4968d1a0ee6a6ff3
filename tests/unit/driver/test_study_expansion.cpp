#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/run/solver_process.hpp"
#include "driver/study/study.hpp"

namespace bd = boycott::driver;

namespace {

const char* kSmall = R"(
name = "small"
[base]
scene = "inclined_settling"
[base.time]
end = 2.0
average_from = 1.0
[[group]]
name = "base"
[[group]]
name = "visc"
set = { "fluid.viscosity" = 1.0e-2, "particles.density" = 1500.0 }
[matrix]
"gravity.angle_deg" = [30, 60, 90]
"seed" = [1, 2]
)";

// The same study: groups, set keys, matrix keys and base sections in another order, a group
// renamed, nested instead of dotted keys.
const char* kSmallReordered = R"(
[[group]]
name = "viscous"
set = { particles = { density = 1500.0 }, "fluid.viscosity" = 0.01 }
[[group]]
name = "reference"
[matrix]
"seed" = [2, 1]
"gravity.angle_deg" = [90, 60, 30]
[base.time]
average_from = 1.0
end = 2.0
[base]
scene = "inclined_settling"
)";

std::set<std::string> ids_of(const bd::Study& s) {
  std::set<std::string> ids;
  for (const auto& c : s.cases) ids.insert(c.id);
  return ids;
}

std::string error_of(const std::string& text) {
  try {
    bd::expand_study_string(text, "test.toml");
  } catch (const boycott::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(StudyExpansion, PaperStudyHas64DistinctValidCases) {
  const auto s = bd::expand_study_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/paper.toml");
  EXPECT_EQ(s.name, "paper");
  ASSERT_EQ(s.cases.size(), 64u);
  EXPECT_EQ(ids_of(s).size(), 64u);
  EXPECT_EQ(s.groups, (std::vector<std::string>{"base", "Ga145.6", "Sr0.0667", "Sg1.5"}));
  std::set<double> angles;
  for (const auto& c : s.cases) {
    angles.insert(c.params.gravity.angle_deg);
    if (c.group == "Ga145.6") {
      EXPECT_DOUBLE_EQ(c.params.fluid.viscosity_pa_s, 1.0e-2);
    }
    if (c.group == "Sr0.0667") {
      EXPECT_DOUBLE_EQ(c.params.particles.diameter_m, 0.4e-3);
      EXPECT_EQ(c.params.particles.count, 405000);
    }
    if (c.group == "Sg1.5") {
      EXPECT_DOUBLE_EQ(c.params.particles.density_kg_m3, 1500.0);
    }
    if (c.group == "base") {
      EXPECT_EQ(c.params.particles.count, 120000);
      EXPECT_NEAR(c.params.solid_fraction(), 0.113, 0.001);
    }
  }
  EXPECT_EQ(angles.size(), 16u);
  EXPECT_EQ(*angles.begin(), 15.0);
  EXPECT_EQ(*angles.rbegin(), 90.0);
}

TEST(StudyExpansion, MatrixIsCartesianProductWithinEveryGroup) {
  const auto s = bd::expand_study_string(kSmall);
  EXPECT_EQ(s.cases.size(), 2u * 3u * 2u);
  EXPECT_EQ(ids_of(s).size(), 12u);
}

TEST(StudyExpansion, IdsAreStableUnderReorderingAndRenaming) {
  const std::string reordered = std::string("name = \"renamed\"\n") + kSmallReordered;
  const auto a = bd::expand_study_string(kSmall);
  const auto b = bd::expand_study_string(reordered);
  EXPECT_EQ(ids_of(a), ids_of(b));
}

TEST(StudyExpansion, DistinctParametersGiveDistinctIds) {
  std::string other = kSmall;
  other.replace(other.find("average_from = 1.0"), 18, "average_from = 1.5");
  const auto a = ids_of(bd::expand_study_string(kSmall));
  const auto b = ids_of(bd::expand_study_string(other));
  for (const auto& id : a) EXPECT_EQ(b.count(id), 0u) << id;
}

TEST(StudyExpansion, RaisingTheEndKeepsEveryId) {
  // Identity version 2: time.end is the run's length, not the case.
  std::string other = kSmall;
  other.replace(other.find("end = 2.0"), 9, "end = 2.5");
  EXPECT_EQ(ids_of(bd::expand_study_string(kSmall)), ids_of(bd::expand_study_string(other)));
}

TEST(StudyExpansion, ZipIsZippedAndCombinedWithMatrixAsProduct) {
  const auto s = bd::expand_study_string(R"(
name = "z"
[matrix]
"gravity.angle_deg" = [45, 90]
[zip]
"particles.diameter" = [0.4e-3, 0.6e-3, 0.8e-3]
"particles.count" = [4000, 1200, 500]
)");
  ASSERT_EQ(s.cases.size(), 6u);
  for (const auto& c : s.cases) {
    if (c.params.particles.diameter_m == 0.4e-3) {
      EXPECT_EQ(c.params.particles.count, 4000);
    }
    if (c.params.particles.diameter_m == 0.6e-3) {
      EXPECT_EQ(c.params.particles.count, 1200);
    }
    if (c.params.particles.diameter_m == 0.8e-3) {
      EXPECT_EQ(c.params.particles.count, 500);
    }
  }
  EXPECT_EQ(s.cases[0].group, "base");  // no [[group]]: one group named base
}

TEST(StudyExpansion, GroupMatrixVariesOneSettingAndCombinesWithTheStudyMatrix) {
  const auto s = bd::expand_study_string(R"(
name = "wp"
[[group]]
name = "reference"
set = { "time.dt_dem" = 1.0e-5 }
[[group]]
name = "dt_cfd"
[group.matrix]
"time.dt_cfd" = [5.0e-4, 2.0e-3]
[matrix]
"gravity.angle_deg" = [65, 90]
)");
  ASSERT_EQ(s.cases.size(), 6u);  // 1 x 2 angles + 2 x 2 angles
  int n_dt_cfd = 0;
  for (const auto& c : s.cases) {
    if (c.group != "dt_cfd") continue;
    ++n_dt_cfd;
    ASSERT_EQ(c.swept.size(), 2u);
    EXPECT_EQ(c.swept[0].first, "time.dt_cfd");  // the group's own axis first, then the study's
    EXPECT_EQ(c.swept[1].first, "gravity.angle_deg");
    EXPECT_TRUE(c.params.time.dt_cfd_s == 5.0e-4 || c.params.time.dt_cfd_s == 2.0e-3);
  }
  EXPECT_EQ(n_dt_cfd, 4);
  EXPECT_THROW(bd::expand_study_string(R"(
name = "bad"
[[group]]
name = "g"
[group.matrix]
"time.no_such_key" = [1, 2]
)"),
               boycott::InputError);
}

TEST(StudyExpansion, CaseFileWrittenForTheSolverHasTheSameId) {
  const auto file = (std::filesystem::path(::testing::TempDir()) / bd::kCaseFileName).string();
  for (const auto& c : bd::expand_study_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/paper.toml").cases) {
    std::ofstream(file) << bd::case_file_text(c.params);
    const auto p = boycott::load_case_file(file, {});
    EXPECT_EQ(boycott::case_id(p), c.id);
    EXPECT_EQ(boycott::to_json(p), boycott::to_json(c.params));
  }
  std::filesystem::remove(file);
}

TEST(StudyExpansion, EveryShippedStudyExpandsToValidCases) {
  // the study files under studies/ are what users run first; each must expand and validate
  namespace fs = std::filesystem;
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(BOYCOTT_SOURCE_DIR) / "studies")) {
    if (e.path().extension() != ".toml") continue;
    ++files;
    SCOPED_TRACE(e.path().string());
    const auto st = bd::expand_study_file(e.path().string());
    EXPECT_FALSE(st.cases.empty());
    for (const auto& c : st.cases) {
      auto p = boycott::case_from_json(nlohmann::json::parse(bd::case_file_text(c.params)));
      EXPECT_NO_THROW(boycott::validate(p));
    }
  }
  EXPECT_GE(files, 8);
}

// A case's id names its runs in every database: a change to how cases are read or written (a
// new key, a new kind of value) must leave the ids of cases that do not use it as they were.
TEST(StudyExpansion, ShippedStudiesKeepTheirCaseIds) {
  namespace fs = std::filesystem;
  std::map<std::string, std::vector<std::string>> want;
  std::ifstream in(fs::path(BOYCOTT_SOURCE_DIR) / "tests" / "data" / "study_case_ids.csv");
  ASSERT_TRUE(in.good());
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') {
      const auto comma = line.find(',');
      want[line.substr(0, comma)].push_back(line.substr(comma + 1));
    }
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(BOYCOTT_SOURCE_DIR) / "studies")) {
    if (e.path().extension() != ".toml") continue;
    ++files;
    std::vector<std::string> got;
    for (const auto& c : bd::expand_study_file(e.path().string()).cases) got.push_back(c.id);
    const auto name = e.path().filename().string();
    EXPECT_EQ(got, want[name]) << name << ": its case ids changed";
  }
  EXPECT_EQ(files, want.size()) << "a study was added or removed: regenerate tests/data/study_case_ids.csv";
}

TEST(StudyExpansionErrors, NameTheOffendingKey) {
  EXPECT_NE(error_of("name = \"x\"\n[base\n").find("malformed TOML"), std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[base.fluid]\nviscosityy = 1e-3\n").find("fluid.viscosityy"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[[group]]\nname = \"g\"\nset = { \"fluid.viscosity\" = -1e-3 }\n")
                .find("fluid.viscosity = -0.001 is out of range"),
            std::string::npos);
  EXPECT_NE(
      error_of(
          "name = \"x\"\n[base.particles]\ncount = 100\n[matrix]\n\"particles.diameter\" = [1e-3, 7e-3]\n")
          .find("does not fit the channel"),
      std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[matrix]\n\"gravity.angel_deg\" = [10]\n").find("gravity.angel_deg"),
            std::string::npos);
  EXPECT_NE(
      error_of("name = \"x\"\n[zip]\n\"seed\" = [1, 2]\n\"gravity.angle_deg\" = [10]\n").find("equally long"),
      std::string::npos);
  EXPECT_NE(error_of("[base]\nseed = 2\n").find("'name'"), std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\nmatrx = 1\n").find("'matrx'"), std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\n[[group]]\nname = \"a\"\n[[group]]\nname = \"b\"\n").find("same case"),
            std::string::npos);
  for (const char* bad : {"name = \"x\"\n[base\n", "name = \"x\"\n[base.fluid]\nviscosityy = 1e-3\n"})
    EXPECT_EQ(error_of(bad).find('\n'), std::string::npos) << "errors are one line";
}

TEST(StudyExpansionErrors, NameTheFileAndTheLineThatSetTheValue) {
  auto message = [](const std::string& text) {
    try {
      bd::expand_study_string(text, "s.toml");
    } catch (const boycott::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  // [base] (as a sub-table), a group's set (inline and as a table), the study's [matrix] with a
  // quoted dotted key, and an unknown key: each names the line that wrote it.
  EXPECT_EQ(message("name = \"x\"\n[base.fluid]\nviscosity = \"thick\"\n").rfind("s.toml:3: ", 0), 0u)
      << message("name = \"x\"\n[base.fluid]\nviscosity = \"thick\"\n");
  const std::string group_set =
      "name = \"x\"\n[base]\ntime.end = 1\ntime.average_from = 0.5\n[[group]]\nname = \"a\"\n[[group]]\n"
      "name = \"b\"\n[group.set]\nfluid.viscosity = -2e-3\n";
  EXPECT_EQ(message(group_set).rfind("s.toml:10: group 'b'", 0), 0u) << message(group_set);
  const std::string matrix =
      "name = \"x\"\n[base]\ntime.end = 1\ntime.average_from = 0.5\n[matrix]\n\"gravity.angle_deg\" = [30, "
      "600]\n";
  EXPECT_EQ(message(matrix).rfind("s.toml:6: ", 0), 0u) << message(matrix);
  EXPECT_NE(message(matrix).find("gravity.angle_deg = 600 is out of range"), std::string::npos);
  // The study's [matrix] is applied after [base]: the line named is the value that was used.
  const std::string both =
      "name = \"x\"\n[base]\ngravity.angle_deg = 95\ntime.end = 1\n"
      "time.average_from = 0.5\n[matrix]\ngravity.angle_deg = [95]\n";
  EXPECT_EQ(message(both).rfind("s.toml:7: ", 0), 0u) << message(both);
  EXPECT_EQ(message("name = \"x\"\n\n[matrix]\n\"gravity.angel_deg\" = [10]\n").rfind("s.toml:4: ", 0), 0u);
  // A value no line sets (a scene's default against a key the file sets) names no line.
  EXPECT_EQ(message("name = \"x\"\n[base]\ntime.end = 0.1\n").find("s.toml:"), std::string::npos);
}

// The pre-flight is part of the one check of a case: a case the coupled solver cannot represent
// is refused when the study is read (by study plan, run or submit alike), naming the case.
TEST(StudyExpansionErrors, APreflightErrorRefusesTheStudyWhenItIsRead) {
  const std::string text =
      "name = \"x\"\n[base]\nscene = \"sediment_transport\"\n[matrix]\n\"gravity.angle_deg\" = [0, 30]\n";
  try {
    bd::expand_study_string(text, "s.toml");
    ADD_FAILURE() << "a sediment_transport case at 30 deg was accepted";
  } catch (const boycott::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("gravity.angle_deg=30"), std::string::npos) << m;
    EXPECT_NE(m.find("must be 0"), std::string::npos) << m;
  }
}

// A study's values reach the case as parsed data: an integer given for a real key, a string, an
// array and a boolean give the same case as the same values in a case file.
TEST(StudyExpansion, StudyValuesGiveTheCaseTheSameValuesAsACaseFile) {
  const auto st = bd::expand_study_string(
      "name = \"x\"\n[base]\nscene = \"inclined_settling\"\n[[group]]\nname = \"g\"\n[group.set]\n"
      "\"domain.cells\" = [10, 3, 20]\n\"domain.periodic_y\" = false\n\"fluid.viscosity\" = 0.002\n"
      "[matrix]\n\"gravity.angle_deg\" = [60]\n\"forces.lift\" = [\"none\"]\n");
  ASSERT_EQ(st.cases.size(), 1u);
  auto p = boycott::parse_case_string(
      "scene = \"inclined_settling\"\n[domain]\ncells = [10, 3, 20]\nperiodic_y = false\n[fluid]\n"
      "viscosity = 0.002\n[gravity]\nangle_deg = 60\n[forces]\nlift = \"none\"\n");
  boycott::validate(p);
  EXPECT_EQ(st.cases[0].id, boycott::case_id(p));
  EXPECT_EQ(boycott::to_json(st.cases[0].params), boycott::to_json(p));
}

TEST(StudyLauncher, WrapsTheCaseInMpirunForSeveralRanks) {
  const auto one = bd::case_command({"boycott"}, 1, "c.toml", "d");
  EXPECT_EQ(one, (std::vector<std::string>{"boycott", "case", "run", "c.toml", "--out", "d", "--quiet"}));
  const auto four = bd::case_command({"boycott"}, 4, "c.toml", "d");
  EXPECT_EQ(four, (std::vector<std::string>{"mpirun", "-n", "4", "--allow-run-as-root", "boycott", "case",
                                            "run", "c.toml", "--out", "d", "--quiet"}));
}

TEST(StudyExpansion, DemoStudyIsValidWithThePaperSolidFractionAndThreeReplicasPerAngle) {
  const auto s = bd::expand_study_file(std::string(BOYCOTT_SOURCE_DIR) + "/studies/demo.toml");
  ASSERT_EQ(s.cases.size(), 12u);  // 4 angles x 3 replicas: an error from their scatter at each
  for (const auto& c : s.cases) EXPECT_NEAR(c.params.solid_fraction(), 0.113, 0.002);
}

namespace {
const char* kReplicated = R"(
name = "rep"
replicas = 3
[base]
scene = "inclined_settling"
seed = 5
[base.time]
end = 2.0
average_from = 1.0
[[group]]
name = "base"
[[group]]
name = "visc"
replicas = 2
set = { "fluid.viscosity" = 1.0e-2 }
[matrix]
"gravity.angle_deg" = [60, 90]
)";
}  // namespace

TEST(StudyReplicas, ReplicaKRunsWithSeedPlusKAndReplicaZeroIsTheCaseAsBefore) {
  const auto s = bd::expand_study_string(kReplicated);
  ASSERT_EQ(s.cases.size(), 2u * 3u + 2u * 2u);
  EXPECT_EQ(ids_of(s).size(), s.cases.size());
  EXPECT_EQ(s.replica_plans.at("base").replicas, 3);
  EXPECT_EQ(s.replica_plans.at("visc").replicas, 2);
  // Replica 0 of every point is the case of the same study without replicas.
  std::string plain = kReplicated;
  plain.replace(plain.find("replicas = 3"), 12, "");
  plain.replace(plain.find("replicas = 2"), 12, "");
  const auto without = bd::expand_study_string(plain);
  std::set<std::string> zero;
  for (const auto& c : s.cases) {
    if (c.replica == 0) {
      zero.insert(c.id);
      EXPECT_EQ(c.point_id, c.id);
    }
    const auto& r0 = *std::find_if(s.cases.begin(), s.cases.end(),
                                   [&](const bd::StudyCase& x) { return x.id == c.point_id; });
    EXPECT_EQ(c.params.seed, 5 + c.replica);
    EXPECT_EQ(c.group, r0.group);
    EXPECT_EQ(c.params.gravity.angle_deg, r0.params.gravity.angle_deg);
    EXPECT_EQ(c.swept, r0.swept) << "replicas share their point's swept values (no seed)";
  }
  EXPECT_EQ(zero, ids_of(without));
  // The first round (replica 0 of every point of a group) comes first.
  EXPECT_EQ(s.cases[0].replica, 0);
  EXPECT_EQ(s.cases[1].replica, 0);
  EXPECT_EQ(s.cases[2].replica, 1);
}

TEST(StudyReplicas, RefusedWithASweptSeedOrAScenelessSeedOrBadCounts) {
  const std::string seeds = error_of(
      "name = \"x\"\nreplicas = 2\n[base.time]\nend = 2.0\naverage_from = 1.0\n[matrix]\nseed = [1, 2]\n");
  EXPECT_NE(seeds.find("replicas = 2"), std::string::npos) << seeds;
  EXPECT_NE(seeds.find("'seed'"), std::string::npos) << seeds;
  const std::string channel =
      error_of("name = \"x\"\nreplicas = 2\n[base]\nscene = \"channel_flow\"\n[base.time]\nend = 0.1\n");
  EXPECT_NE(channel.find("channel_flow does not read"), std::string::npos) << channel;
  const std::string single = error_of(
      "name = \"x\"\n[base]\nscene = \"single_particle\"\n[base.time]\nend = 0.1\naverage_from = 0.05\n"
      "[[group]]\nname = \"g\"\nreplicas = 3\n");
  EXPECT_NE(single.find("single_particle does not read"), std::string::npos) << single;
  EXPECT_NE(error_of("name = \"x\"\nreplicas = 0\n").find("replicas must be a whole number"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\nreplicas = 2.5\n").find("replicas must be a whole number"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\nreplicas_max = 4\n[base.time]\nend = 2.0\naverage_from = 1.0\n")
                .find("replicas_target_rel_error, which is not set"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\nreplicas = 5\nreplicas_max = 3\nreplicas_target_rel_error = 0.01\n"
                     "[base.time]\nend = 2.0\naverage_from = 1.0\n")
                .find("replicas_max = 3 is below"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"x\"\nreplicas_target_rel_error = 2\n").find("in (0, 1)"), std::string::npos);
  // A seed set once for a group is not a sweep.
  EXPECT_NO_THROW(bd::expand_study_string(
      "name = \"x\"\nreplicas = 2\n[base.time]\nend = 2.0\naverage_from = 1.0\n[[group]]\nname = \"g\"\n"
      "set = { seed = 7 }\n"));
}

TEST(StudyReplicas, ATargetStartsWithThreeReplicasUpToTenByDefault) {
  const auto s = bd::expand_study_string(
      "name = \"x\"\nreplicas_target_rel_error = 0.02\n[base.time]\nend = 2.0\naverage_from = 1.0\n"
      "[[group]]\nname = \"a\"\n[[group]]\nname = \"b\"\nreplicas_max = 4\nreplicas = 3\n"
      "set = { \"fluid.viscosity\" = 2e-3 }\n");
  EXPECT_EQ(s.replica_plans.at("a").replicas, 3);
  EXPECT_EQ(s.replica_plans.at("a").max, 10);
  EXPECT_DOUBLE_EQ(*s.replica_plans.at("a").target_rel_error, 0.02);
  EXPECT_EQ(s.replica_plans.at("b").replicas, 3);
  EXPECT_EQ(s.replica_plans.at("b").max, 4);
  EXPECT_EQ(s.cases.size(), 6u);
  const auto r = bd::replica_of(s.cases[0], 7);
  EXPECT_EQ(r.params.seed, s.cases[0].params.seed + 7);
  EXPECT_EQ(r.point_id, s.cases[0].id);
}

TEST(StudyExpansion, SweptDoublesReadAsTheShortestTextThatReadsBackTheSame) {
  EXPECT_EQ(bd::readable_value("0.80000000000000004"), "0.8");
  EXPECT_EQ(bd::readable_value("0.029999999999999999"), "0.03");
  EXPECT_EQ(bd::readable_value("1.0000000000000001e-05"), "1e-05");
  EXPECT_EQ(bd::readable_value("0.1234567890123"), "0.1234567890123");
  // Integers, strings and arrays are left as they are.
  EXPECT_EQ(bd::readable_value("65"), "65");
  EXPECT_EQ(bd::readable_value("\"kernel\""), "\"kernel\"");
  EXPECT_EQ(bd::readable_value("[20, 6, 40]"), "[20, 6, 40]");
}

TEST(StudyExpansion, NamesThatWouldLeaveTheirFolderOrReachTheTerminalRawAreRefused) {
  auto error_of = [](const std::string& text) {
    try {
      bd::expand_study_string(text);
    } catch (const boycott::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error_of("name = \"..\"\n").find("('.' or '..')"), std::string::npos);
  EXPECT_NE(error_of("name = \"a/b\"\n").find("path separator"), std::string::npos);
  EXPECT_NE(error_of("name = \"ok\"\n[[group]]\nname = \"x\\u0000y\"\n").find("control character 0x00"),
            std::string::npos);
  EXPECT_NE(error_of("name = \"ok\"\n[[group]]\nname = \"\\u001b[31mred\"\n").find("control character 0x1b"),
            std::string::npos);
  EXPECT_EQ(error_of("name = \"a b,c\"\n[[group]]\nname = \"Ga145.6\"\n"), "accepted");
}
