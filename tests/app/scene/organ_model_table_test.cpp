// The organ model table (app/scene/organ_model_table.hpp) is complete and is what the program
// asks: every ModelKind has one row in both halves, its name parses back, each model warns about
// exactly the keys it ignores, and `check` names each model's own default material.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "app/check/scene_sanity.hpp"
#include "app/scene/organ_model_table.hpp"
#include "app/scene/scene.hpp"
#include "app/scene/scene_keys.hpp"
#include "app/simulation/organ_models.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// Every ModelKind: the engine names each one (its switch covers them all) and no other.
std::vector<vdm::ModelKind> every_model_kind() {
  std::vector<vdm::ModelKind> kinds;
  for (int i = 0; i < 64 && std::string(vdm::to_string(static_cast<vdm::ModelKind>(i))) != "unknown"; ++i)
    kinds.push_back(static_cast<vdm::ModelKind>(i));
  return kinds;
}

TEST(OrganModelTable, EveryModelKindHasOneRowInBothHalvesAndItsNameParsesBack) {
  const std::vector<vdm::ModelKind> kinds = every_model_kind();
  ASSERT_GE(kinds.size(), 4u);
  EXPECT_EQ(organ_models().size(), kinds.size());
  EXPECT_EQ(organ_model_names().size(), kinds.size());
  for (vdm::ModelKind kind : kinds) {
    const std::string name = vdm::to_string(kind);
    SCOPED_TRACE(name);
    int rows = 0;
    for (const OrganModel& m : organ_models()) rows += m.kind == kind;
    EXPECT_EQ(rows, 1);
    EXPECT_EQ(organ_model(kind).kind, kind);
    EXPECT_EQ(organ_model_run(kind).kind, kind);
    vdm::ModelKind parsed = kind == vdm::ModelKind::vdm ? vdm::ModelKind::fem : vdm::ModelKind::vdm;
    EXPECT_TRUE(vdm::parse_model_kind(name, parsed));
    EXPECT_EQ(parsed, kind);
    EXPECT_EQ(organ_model(kind).name(), name);
    EXPECT_FALSE(organ_model(kind).material.empty()) << "check names no default material";
  }
}

TEST(OrganModelTable, DefaultModelIsTheScenesAndTheReferencesDefault) {
  EXPECT_EQ(OrganDef().model, kDefaultOrganModel);
  for (const SceneKey& k : kSceneKeys)
    if (std::string(k.path) == "organ.model") {
      EXPECT_EQ(k.default_value(), vdm::to_string(kDefaultOrganModel));
      EXPECT_EQ(k.values(), organ_model_names());
    }
}

TEST(OrganModelTable, ModelKeysAreOrganOrSolverKeysEachUsedBySomeButNotAllModels) {
  const std::vector<std::string> keys = model_specific_keys();
  ASSERT_FALSE(keys.empty());
  for (const std::string& path : keys) {
    SCOPED_TRACE(path);
    EXPECT_TRUE(path.rfind("organ.", 0) == 0 || path.rfind("simulation.solver", 0) == 0);
    int users = 0;
    for (const OrganModel& m : organ_models()) users += m.uses(path);
    EXPECT_GT(users, 0);
    EXPECT_LT(users, static_cast<int>(organ_models().size()));
  }
  // A key no row lists is every model's.
  for (const OrganModel& m : organ_models()) EXPECT_TRUE(m.uses("organ.material.density")) << m.name();
}

// A scene of `model` on the project's small liver with the key `path` set to the value of its
// own example in the scene reference.
std::vector<SceneProblem> model_table_scene_problems(const std::string& model, const std::string& path) {
  const std::string name = path.substr(path.rfind('.') + 1);
  const YAML::Node example = YAML::Load(std::string("{") + kSceneKeys[scene_key_index(path.c_str())].example + "}");
  YAML::Node root = YAML::Load("{organ: {}}");
  root["organ"]["mesh"] = (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string();
  root["organ"]["model"] = model;
  if (path.rfind("organ.material.", 0) == 0) root["organ"]["material"][name] = example[name];
  else if (path.rfind("organ.", 0) == 0) root["organ"][name] = example[name];
  else if (path == "simulation.solver") root["simulation"]["solver"] = example[name];
  else root["simulation"]["solver"][name] = example[name];
  YAML::Emitter e;
  e << root;
  const fs::path file = test::scratch_dir("organ_model_table") / (model + "_" + name + ".yaml");
  std::ofstream(file) << e.c_str() << "\n";
  return load_scene(file.string()).problems;
}

// Once each: a key inside an ignored section is warned at the section.
TEST(OrganModelTable, EachModelWarnsAboutExactlyTheKeysItIgnores) {
  for (const OrganModel& m : organ_models())
    for (const std::string& path : model_specific_keys()) {
      SCOPED_TRACE(std::string(m.name()) + " " + path);
      // The outermost model-specific key holding `path` (the keys come sections first).
      std::string field = path;
      for (const std::string& k : model_specific_keys())
        if (path.rfind(k + ".", 0) == 0) {
          field = k;
          break;
        }
      int ignored = 0;
      for (const SceneProblem& p : model_table_scene_problems(m.name(), path))
        if (p.message.find("ignored by organ.model") != std::string::npos) {
          ++ignored;
          EXPECT_TRUE(p.warning);
          EXPECT_EQ(p.field, field);
          EXPECT_EQ(p.message, std::string("ignored by organ.model ") + m.name() +
                                   " (docs/scene-reference.md says which models use it)");
        }
      EXPECT_EQ(ignored, m.uses(path) ? 0 : 1);
    }
}

TEST(OrganModelTable, InertiaOnAStaticModelIsWarnedAbout) {
  // The inertia effect on a model whose steps are static changes nothing: a warning at the
  // effect, naming the models that take it; none on those that do.
  for (const OrganModel& m : organ_models()) {
    SCOPED_TRACE(m.name());
    const fs::path file = test::scratch_dir("organ_model_table") / (std::string(m.name()) + "_inertia.yaml");
    std::ofstream(file) << "organ:\n  mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                        << "\n  model: " << m.name() << "\nsimulation:\n  effects: [gravity, inertia]\n";
    int warned = 0;
    for (const SceneProblem& p : load_scene(file.string()).problems)
      if (p.field == "simulation.effects[1]") {
        ++warned;
        EXPECT_TRUE(p.warning);
        EXPECT_NE(p.message.find("its steps are static (inertia needs organ.model vdm or vdm_core)"), std::string::npos)
            << p.message;
      }
    EXPECT_EQ(warned, m.inertia ? 0 : 1);
  }
}

TEST(OrganModelTable, CheckNamesEachModelsOwnDefaultMaterial) {
  const std::vector<std::pair<vdm::ModelKind, std::string>> expected = {
      {vdm::ModelKind::vdm, "bulk_modulus 20000 Pa, connectivity_modulus 2000 Pa, density 1060 kg/m^3"},
      {vdm::ModelKind::vdm_core, "young_modulus 3000 Pa, poisson_ratio 0.45, density 1060 kg/m^3"},
      {vdm::ModelKind::fem, "young_modulus 3000 Pa, poisson_ratio 0.45, density 1060 kg/m^3"},
      {vdm::ModelKind::mass_spring, "young_modulus 3000 Pa, thickness 0.005 m, density 1060 kg/m^3"}};
  for (const auto& [kind, values] : expected) {
    PreparedScene ps;
    ps.scene.organ().model = kind;
    std::string said;
    for (const SceneProblem& p : scene_sanity(ps).problems)
      if (p.field == "organ.material") said = p.message;
    EXPECT_EQ(said, "not given: the default material is used (" + values + "); give your tissue's")
        << vdm::to_string(kind);
  }
}

}  // namespace
}  // namespace vdmsim
