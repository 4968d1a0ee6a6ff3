// Each registry that turns a model's name into code knows exactly the names of its list in
// core/model_names.hpp and core/scene_specs.hpp (the lists parsing and `case keys` read).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/case_params.hpp"
#include "core/error.hpp"
#include "core/key_docs.hpp"
#include "core/model_names.hpp"
#include "core/scene_specs.hpp"
#include "coupling/drag_laws.hpp"
#include "coupling/fluid_fields.hpp"
#include "coupling/kernels.hpp"
#include "coupling/lift_laws.hpp"
#include "coupling/sampling.hpp"
#include "particles/contact_models.hpp"
#include "scenes/scene.hpp"

namespace boycott {
namespace {

TEST(ModelRegistries, SceneTableHoldsExactlyTheListedScenes) {
  auto listed = scene_names(), registered = scenes::registered_scenes();
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(registered, listed);
  for (const auto& name : scene_names()) EXPECT_NE(scenes::find_scene(name), nullptr) << name;
  EXPECT_THROW(scenes::find_scene("hindered_settling"), InputError);
}

TEST(ModelRegistries, DragLawsResolveExactlyTheListedNames) {
  std::vector<std::string> resolved;
  for (const auto& name : drag_law_names())
    resolved.push_back(coupling::visit_drag_law(name, [](const auto& law) { return std::string(law.name); }));
  EXPECT_EQ(resolved, drag_law_names());
  EXPECT_THROW(coupling::visit_drag_law("ergun_only", [](const auto&) { return 0; }), InputError);
}

TEST(ModelRegistries, KernelsResolveExactlyTheListedNames) {
  for (const auto& name : kernel_names()) EXPECT_NO_THROW(coupling::kernel_from_name(name)) << name;
  EXPECT_THROW(coupling::kernel_from_name("gaussian"), InputError);
}

TEST(ModelRegistries, LiftLawsResolveExactlyTheListedNames) {
  for (const auto& name : lift_law_names()) EXPECT_NO_THROW(coupling::lift_law_from_name(name)) << name;
  EXPECT_THROW(coupling::lift_law_from_name("magnus"), InputError);
}

TEST(ModelRegistries, VorticitiesResolveExactlyTheListedNames) {
  for (const auto& name : vorticity_names())
    EXPECT_NO_THROW(coupling::edge_vorticity_from_name(name)) << name;
  EXPECT_THROW(coupling::edge_vorticity_from_name("nodes"), InputError);
}

TEST(ModelRegistries, SamplingsResolveExactlyTheListedNames) {
  for (const auto& name : sampling_names()) EXPECT_NO_THROW(coupling::sampling_from_name(name)) << name;
  EXPECT_THROW(coupling::sampling_from_name("nearest"), InputError);
}

TEST(ModelRegistries, ContactAndRollingModelsResolveExactlyTheListedNames) {
  for (const auto& name : contact_model_names())
    EXPECT_NO_THROW(particles::check_contact_model(name)) << name;
  EXPECT_THROW(particles::check_contact_model("hertz_mindlin"), InputError);
  for (const auto& name : rolling_model_names())
    EXPECT_NO_THROW(particles::rolling_model_enabled(name)) << name;
  EXPECT_THROW(particles::rolling_model_enabled("viscous"), InputError);
}

TEST(ModelRegistries, EverySceneReadsOnlyKeysThatExist) {
  // A scene's list of keys names sections and keys of the key table, nothing else.
  const auto keys = case_key_names();
  for (const auto& sc : scene_specs()) {
    for (const auto& r : sc.reads) {
      const bool found = std::any_of(keys.begin(), keys.end(), [&](const std::string& k) {
        return k == r || (r.back() == '.' && k.rfind(r, 0) == 0);
      });
      EXPECT_TRUE(found) << sc.name << " reads unknown '" << r << "'";
    }
    for (const auto& [k, v] : sc.defaults)
      EXPECT_TRUE(scene_reads(sc, k)) << sc.name << " defaults unread " << k;
  }
}

TEST(KeyDocs, EveryCaseKeyHasAUnitAndAMeaning) {
  // `boycott case keys` prints these; a key added without them fails here.
  for (const auto& k : case_key_names()) {
    const auto doc = key_doc(k);
    ASSERT_TRUE(doc.has_value()) << k << " has no entry in core/key_docs.cpp";
    EXPECT_GT(doc->meaning.size(), 10u) << k;
  }
  EXPECT_FALSE(key_doc("fluid.viscosty").has_value());
}

TEST(KeyDocs, UnitsAndChoicesComeFromTheKeyTable) {
  // One table declares each key: its unit is the rule's, a name key lists its model list.
  EXPECT_EQ(key_doc("fluid.viscosity")->unit, "Pa s");
  EXPECT_EQ(key_doc("particles.count")->unit, "-");   // a pure number
  EXPECT_EQ(key_doc("forces.added_mass")->unit, "");  // a flag
  EXPECT_EQ(key_doc("forces.drag")->unit, "");        // a name
  for (const auto& law : drag_law_names())
    EXPECT_NE(key_doc("forces.drag")->meaning.find(law), std::string::npos) << law;
  for (const auto& law : lift_law_names())
    EXPECT_NE(key_doc("forces.lift")->meaning.find(law), std::string::npos) << law;
}

TEST(KeyDocs, MisspeltKeysSuggestTheNearestAndUnrelatedWordsNothing) {
  EXPECT_EQ(did_you_mean("fluid.viscosty"), " (did you mean 'fluid.viscosity'?)");
  EXPECT_EQ(did_you_mean("time.dt_dme"), " (did you mean 'time.dt_dem'?)");
  EXPECT_EQ(did_you_mean("gravity.viscosity"), " (did you mean 'fluid.viscosity'?)");  // wrong section
  EXPECT_EQ(did_you_mean("zzzzzzzz.qqqq"), "");
  try {
    CaseParams p;
    apply_override(p, "particles.diamter=1e-3");
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'particles.diameter'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace boycott
