#include <filesystem>
#include <fstream>

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

TEST(CaseParams, AnErrorInAFileNamesTheFileAndLine) {
  const auto dir = std::filesystem::temp_directory_path() / "boycott_case_lines";
  std::filesystem::create_directories(dir);
  auto message = [&](const std::string& text, const std::vector<std::string>& sets = {}) {
    const auto file = (dir / "c.toml").string();
    std::ofstream(file) << text;
    try {
      load_case_file(file, sets);
    } catch (const InputError& e) {
      // The path's folder varies with the machine: compared from the file's name on.
      const std::string what = e.what();
      const auto at = what.find("c.toml");
      return at == std::string::npos ? what : what.substr(at);
    }
    return std::string("accepted");
  };
  const std::string head = "scene = \"single_particle\"\n# a comment\n[fluid]\n";
  EXPECT_EQ(message(head + "viscosty = 1e-3\n").rfind("c.toml:4: unknown key 'fluid.viscosty'", 0), 0u);
  EXPECT_EQ(message(head + "viscosity = \"abc\"\n").rfind("c.toml:4: fluid.viscosity must be a number", 0),
            0u);
  EXPECT_EQ(message(head + "density = 1000\nviscosity = -1\n").rfind("c.toml:5: fluid.viscosity = -1", 0),
            0u);
  // Limits between keys name the line of the key the message begins with.
  EXPECT_EQ(message("scene = \"inclined_settling\"\n[time]\nend = 1\naverage_from = 2\n")
                .rfind("c.toml:4: time.average_from = 2 s must be < time.end", 0),
            0u);
  // A value given by --set is not the file's: no line of the file is named.
  const std::string from_set = message(head + "density = 1000\n", {"fluid.viscosity=-1"});
  EXPECT_EQ(from_set.find("c.toml:"), std::string::npos) << from_set;
  std::filesystem::remove_all(dir);
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
  apply_override(p, "particles.count=10000000");
  expect_message(p, "overfills the box");
  // A key the scheme does not use is refused at any value but its default, not ignored.
  p = CaseParams{};
  p.numerics.pressure_relaxation = 0.8;
  expect_message(p, "numerics.pressure_relaxation = 0.8: must be 0.5");
  p = CaseParams{};
  p.numerics.pressure_relaxation = 0.5;
  EXPECT_NO_THROW(validate(p));
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

TEST(CaseParams, IdentityVersion2LeavesOutTheRunLengthAndOutputOnly) {
  // Raising time.end continues a run: it, the checkpoint interval and output.* are not the case.
  CaseParams a;
  validate(a);
  for (const char* change :
       {"time.end=40.0", "time.checkpoint_every=0.5", "output.timeseries_every=0.01",
        "output.keep_checkpoints=5", "output.snapshot_times=[1.0]", "output.pdf_bins=80"}) {
    CaseParams b;
    apply_override(b, change);
    validate(b);
    EXPECT_EQ(case_id(b), case_id(a)) << change;
  }
  // The averaging window is part of the measurement.
  CaseParams c;
  apply_override(c, "time.average_from=6.0");
  validate(c);
  EXPECT_NE(case_id(c), case_id(a));
  // The default case's id under version 2 (a change of the scheme must bump kCaseIdVersion and
  // migrate stored ids, see driver/store/case_id_migration.cpp). Mei's lift, then two SIMPLE
  // correctors, then the packed-bed step limit became the default after it: a case with the
  // defaults of earlier builds keeps its id (no limit: the default case of the build before it;
  // one corrector too: the default case of the build before two; with Saffman's lift too: the
  // default case of the builds before Mei's).
  EXPECT_EQ(case_id(a), "40f6bb317af6f7d7");
  CaseParams no_limit;
  apply_override(no_limit, "numerics.drag_dt_limit=false");
  validate(no_limit);
  EXPECT_EQ(case_id(no_limit), "53efe1afd84e4584");
  CaseParams one_corrector = no_limit;
  apply_override(one_corrector, "numerics.simple_correctors=1");
  validate(one_corrector);
  EXPECT_EQ(case_id(one_corrector), "98d95b7d3ced7ffb");
  CaseParams saffman = one_corrector;
  apply_override(saffman, "forces.lift=\"saffman\"");
  validate(saffman);
  EXPECT_EQ(case_id(saffman), "feaf57c856c9fbc2");
}

TEST(CaseParams, IdHashesOnlyTheKeysTheSceneReads) {
  // channel_flow has no particles: their keys are neither part of its id nor accepted.
  CaseParams a;
  apply_override(a, "scene=\"channel_flow\"");
  validate(a);
  CaseParams b = a;
  b.particles.diameter_m = 1e-3;
  b.contact.stiffness_n_m = 10.0;
  EXPECT_EQ(case_id(b), case_id(a));
  EXPECT_EQ(to_json(a).count("particles"), 0u);
  CaseParams c;
  apply_override(c, "scene=\"channel_flow\"");
  apply_override(c, "particles.count=10");
  try {
    validate(c);
    FAIL() << "particles.count accepted for channel_flow";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particles.count is not used by scene channel_flow"),
              std::string::npos)
        << e.what();
  }
}

TEST(CaseParams, ASceneRefusesKeysItWouldOverwrite) {
  // Coupled scenes set the fluid's body force from gravity: a user's [flow] would be lost.
  CaseParams p;
  apply_override(p, "flow.body_acceleration=[0.0, 0.0, 1.0]");
  EXPECT_THROW(validate(p), InputError);
  // sediment.initial_flow belongs to sediment_transport only.
  CaseParams q;
  apply_override(q, "sediment.initial_flow=\"rest\"");
  EXPECT_THROW(validate(q), InputError);
  CaseParams s, r;
  apply_override(s, "scene=\"sediment_transport\"");
  apply_override(r, "scene=\"sediment_transport\"");
  apply_override(r, "sediment.initial_flow=\"rest\"");
  validate(s);
  validate(r);
  EXPECT_NE(case_id(r), case_id(s));
}

TEST(CaseParams, ParticleCountFollowsTheBoxAtTableIIISolidFraction) {
  // Neither count nor volume fraction: Table III's 0.1130973 in the case's own box.
  EXPECT_NEAR(table3_solid_fraction(), 0.1130973, 1e-7);
  CaseParams a;
  validate(a);
  EXPECT_EQ(a.particles.count, 120000);
  CaseParams b;
  apply_override(b, "particles.diameter=0.4e-3");
  validate(b);
  EXPECT_EQ(b.particles.count, 405000);
  EXPECT_DOUBLE_EQ(b.numerics.neighbor_skin_m, 0.3e-3);
  CaseParams c;
  apply_override(c, "domain.length_x=0.02");
  apply_override(c, "domain.height_z=0.02");
  validate(c);
  EXPECT_EQ(c.particles.count, 2400);
  // The skin follows small particles: min(0.3 mm, d).
  CaseParams d;
  apply_override(d, "particles.diameter=0.1e-3");
  apply_override(d, "time.dt_dem=1e-5");
  apply_override(d, "domain.length_x=0.01");
  apply_override(d, "domain.height_z=0.01");
  validate(d);
  EXPECT_DOUBLE_EQ(d.numerics.neighbor_skin_m, 0.1e-3);
  // A scene's own default load: ergun's packed bed (porosity 0.36).
  CaseParams e;
  apply_override(e, "scene=\"ergun\"");
  apply_override(e, "domain.length_x=0.02");
  apply_override(e, "domain.width_y=0.02");
  apply_override(e, "domain.height_z=0.04");
  apply_override(e, "particles.diameter=1e-3");
  validate(e);
  EXPECT_NEAR(e.solid_fraction(), 0.64, 1e-4);
  EXPECT_EQ(e.particles.insertion, "packed");
  EXPECT_TRUE(e.domain.periodic_y);
}

TEST(CaseParams, CanonicalJsonRoundTripsWithoutReResolving) {
  // params.json holds resolved values; reading it back neither re-derives nor refuses anything.
  CaseParams a;
  apply_override(a, "particles.count=300");
  apply_override(a, "domain.length_x=0.01");
  apply_override(a, "domain.height_z=0.01");
  validate(a);
  CaseParams b = case_from_json(to_json(a));
  validate(b);
  EXPECT_EQ(b.particles.count, 300);
  EXPECT_EQ(case_id(b), case_id(a));
}

// A run's params.json (and the case.json a study writes) is a case file: read back to the same
// case, a --set changing that one value, anything that is not such a record refused by name.
TEST(CaseParams, ACanonicalJsonCaseFileRunsTheSameCaseAndRefusesWhatIsNotOne) {
  const auto dir = std::filesystem::temp_directory_path() / "boycott_json_case";
  std::filesystem::create_directories(dir);
  const auto file = (dir / "case.json").string();
  CaseParams a;
  apply_override(a, "particles.count=300");
  apply_override(a, "domain.length_x=0.01");
  apply_override(a, "domain.height_z=0.01");
  validate(a);
  std::ofstream(file) << to_json(a).dump(2);
  EXPECT_EQ(case_id(load_case_file(file, {})), case_id(a));
  const CaseParams longer = load_case_file(file, {"time.end=30"});
  EXPECT_EQ(longer.time.end_s, 30.0);
  EXPECT_EQ(case_id(longer), case_id(a));  // the run's length is not the case's identity
  EXPECT_NE(case_id(load_case_file(file, {"fluid.viscosity=2e-3"})), case_id(a));
  auto message = [&](const std::string& text, const std::vector<std::string>& sets = {}) {
    std::ofstream(file) << text;
    try {
      load_case_file(file, sets);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  auto with = to_json(a);
  with["fluid"]["viscosty"] = 1e-3;
  EXPECT_NE(message(with.dump()).find("unknown key 'fluid.viscosty'"), std::string::npos);
  EXPECT_NE(message("[1, 2]").find("not a case"), std::string::npos);
  EXPECT_NE(message("{\"scene\": ").find("malformed JSON"), std::string::npos);
  with = to_json(a);
  with["fluid"]["viscosity"] = -1.0;
  EXPECT_NE(message(with.dump()).find("fluid.viscosity = -1"), std::string::npos);
  EXPECT_NE(message(to_json(a).dump(), {"particles.volume_fraction=0.1"}).find("set particles.count"),
            std::string::npos);
  std::filesystem::remove_all(dir);
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

TEST(ExitCodes, EachErrorKindMapsToItsDocumentedCode) {
  // Design brief section 7: 2 input, 3 physics, 4 checkpoint, 74 storage, 1 anything else.
  EXPECT_EQ(exit_code_of(InputError("x")), 2);
  EXPECT_EQ(exit_code_of(PhysicsError("x")), 3);
  EXPECT_EQ(exit_code_of(CheckpointError("x")), 4);
  EXPECT_EQ(exit_code_of(StorageError("x")), 74);
  EXPECT_EQ(exit_code_of(std::runtime_error("x")), 1);
}

TEST(CaseParams, LiftLawIsALateKeyWithOneIdPerPhysics) {
  // forces.lift = "saffman" is the behaviour before the key existed: left out of the id, so every
  // stored case keeps its id (pinned above); Mei's law, the default now, is in the id.
  CaseParams a;
  apply_override(a, "forces.lift=\"saffman\"");
  validate(a);
  nlohmann::json j = to_json(a);
  j["forces"].erase("lift");
  EXPECT_EQ(case_id(a), case_id(case_from_json(j)));
  CaseParams dflt;
  validate(dflt);
  EXPECT_NE(case_id(dflt), case_id(a));
  // "none" is saffman_lift = false: one case, one id, whichever way it is said.
  CaseParams off, none;
  apply_override(off, "forces.saffman_lift=false");
  apply_override(none, "forces.lift=\"none\"");
  validate(off);
  validate(none);
  EXPECT_EQ(case_id(none), case_id(off));
  EXPECT_NE(case_id(off), case_id(a));
  // Mei's law is another case, the default one.
  CaseParams mei;
  apply_override(mei, "forces.lift=\"saffman_mei\"");
  validate(mei);
  EXPECT_NE(case_id(mei), case_id(a));
  EXPECT_EQ(case_id(mei), case_id(dflt));
  EXPECT_NE(case_id(mei), case_id(off));
  // A law other than the default named beside the lift switched off is a contradiction, refused
  // with both keys named (the default law beside it is how a case written back with every key
  // reads: the switch turns it off).
  CaseParams bad;
  apply_override(bad, "forces.saffman_lift=false");
  apply_override(bad, "forces.lift=\"saffman\"");
  try {
    validate(bad);
    FAIL() << "saffman accepted with saffman_lift = false";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("forces.saffman_lift"), std::string::npos) << e.what();
  }
  // The force budget and the velocity profile are output: not the case.
  CaseParams budget;
  apply_override(budget, "output.force_budget_y=true");
  validate(budget);
  EXPECT_EQ(case_id(budget), case_id(dflt));
  CaseParams profile;
  apply_override(profile, "output.velocity_profile_y=true");
  validate(profile);
  EXPECT_EQ(case_id(profile), case_id(dflt));
}

TEST(CaseParams, AStoredRecordWithoutALateKeyHadItsOldBehaviour) {
  // params.json of an earlier build has no forces.lift: it ran Saffman's lift, whatever the
  // default is now, and keeps its id.
  CaseParams a;
  apply_override(a, "forces.lift=\"saffman\"");
  validate(a);
  nlohmann::json old = to_json(a);
  old["forces"].erase("lift");
  old["numerics"].erase("vorticity");
  const CaseParams back = case_from_json(old);
  EXPECT_EQ(back.forces.lift, "saffman");
  EXPECT_EQ(back.numerics.vorticity, "cell_centres");
  EXPECT_EQ(case_id(back), case_id(a));
  // A record that names the key keeps its value.
  CaseParams m;
  apply_override(m, "forces.lift=\"saffman_mei\"");
  validate(m);
  EXPECT_EQ(case_from_json(to_json(m)).forces.lift, "saffman_mei");
  EXPECT_EQ(case_id(case_from_json(to_json(m))), case_id(m));
}

TEST(CaseParams, AverageFromAutoIsTakenByTheSceneThatFindsItsTransientAndTravelsAsAuto) {
  const std::string head = "scene = \"inclined_settling\"\n[time]\nend = 1\n";
  CaseParams a = parse_case_string(head + "average_from = \"auto\"\n");
  validate(a);
  EXPECT_TRUE(a.time.average_from.automatic);
  EXPECT_EQ(a.time.average_from.collect_from_s(), 0.0);
  // Written and read back (params.json, the case file for the solver): still auto, same id.
  const nlohmann::json j = to_json(a);
  EXPECT_EQ(j["time"]["average_from"], "auto");
  CaseParams b = case_from_json(j);
  validate(b);
  EXPECT_TRUE(b.time.average_from.automatic);
  EXPECT_EQ(case_id(b), case_id(a));
  // A number stays a number, with an id of its own; --set takes the bare word.
  CaseParams n = parse_case_string(head + "average_from = 0.5\n");
  validate(n);
  EXPECT_FALSE(n.time.average_from.automatic);
  EXPECT_EQ(to_json(n)["time"]["average_from"], 0.5);
  EXPECT_NE(case_id(n), case_id(a));
  apply_override(n, "time.average_from=auto");
  EXPECT_TRUE(n.time.average_from.automatic);
  // Scenes without the per-step series refuse it, naming the scene; other words are refused.
  auto message = [](const std::string& text) {
    try {
      CaseParams p = parse_case_string(text);
      validate(p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("scene = \"single_particle\"\n[time]\nend = 1\naverage_from = \"auto\"\n")
                .find("time.average_from = \"auto\" is not taken by scene single_particle"),
            std::string::npos);
  EXPECT_NE(
      message(head + "average_from = \"soon\"\n").find("time.average_from must be a number or \"auto\""),
      std::string::npos);
}
