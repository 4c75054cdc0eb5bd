// docs/scene-reference.md is what the scene reader's table of keys prints, and the table is
// true: every key's example loads without a problem, and every value it lists is one the
// reader knows.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <cctype>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/scene/organ_model_table.hpp"
#include "app/scene/scene.hpp"
#include "app/scene/scene_keys.hpp"
#include "app/scene/scene_reference.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

TEST(SceneReference, CommittedPageIsWhatTheCodePrints) {
  std::ostringstream printed;
  write_scene_reference(printed);
  const fs::path page = fs::path(VDMSIM_SOURCE_DIR) / "docs/scene-reference.md";
  std::ifstream in(page);
  ASSERT_TRUE(in) << page << " is missing: run ./build/vdmsim scene-reference > docs/scene-reference.md";
  std::stringstream committed;
  committed << in.rdbuf();
  if (committed.str() == printed.str()) return;
  std::istringstream a(committed.str()), b(printed.str());
  std::string la, lb;
  int line = 0;
  while (true) {
    ++line;
    const bool ga = static_cast<bool>(std::getline(a, la)), gb = static_cast<bool>(std::getline(b, lb));
    if (!ga && !gb) break;
    if (!ga || !gb || la != lb) {
      ADD_FAILURE() << page << " differs from what the code prints, first at line " << line << ":\n  committed: "
                    << (ga ? la : "(end of file)") << "\n  printed:   " << (gb ? lb : "(end of output)")
                    << "\nRegenerate it: ./build/vdmsim scene-reference > docs/scene-reference.md";
      return;
    }
  }
  ADD_FAILURE() << page << " differs from what the code prints (line endings?)";
}

// A scene with every section, for the examples to go into: organ.fixed holds one region of
// each kind (box, sphere, nodes, all), in that order.
const char* kBaseScene = R"(name: base
organ:
  mesh: ../meshes/liver_L4.obj
  material: {density: 1060}
  fixed:
    - {box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}
    - {sphere: {center: [0, 0, 0], radius: 0.01}}
    - {nodes: [1, 2]}
    - {all: true, axes: [z]}
  loads: [{sphere: {center: [0, 0, 0.06], radius: 0.02}, force: [0, 0, -1], t: [0, 1]}]
  prescribed: [{nodes: [5], translate: [0, 0, -0.001]}]
simulation:
  frames: 3
  dt: 0.04
  effects: [contact, stress]
  contact: {method: kinematic}
instruments:
  - type: probe
    radius: 0.004
    script:
      - {t: 0, tip: [0.035, 0, 0.075], axis: [0, 0, -1]}
      - {t: 1, tip: [0.035, 0, 0.05]}
    skin: {body: ../meshes/probe.obj}
render:
  width: 64
  height: 48
  views: [shaded]
  camera: {eye: [0.16, -0.24, 0.19], target: [0.025, 0, 0.025]}
  stress: {quantity: magnitude}
)";

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream s(path);
  std::string p;
  while (std::getline(s, p, '.')) parts.push_back(p);
  return parts;
}

// The mapping of `root` that holds the key `path` (a region's keys: in organ.fixed[k], the
// region of their kind).
YAML::Node holder(YAML::Node root, const std::string& path) {
  std::vector<std::string> parts = split(path);
  parts.pop_back();
  YAML::Node n = root;
  size_t i = 0;
  if (!parts.empty() && parts[0] == "region") {
    const std::vector<std::string> kinds = {"box", "sphere", "nodes", "all"};
    const std::string kind = split(path)[1];
    const size_t k = std::find(kinds.begin(), kinds.end(), kind) - kinds.begin();
    n.reset(root["organ"]["fixed"][k]);
    i = 1;
  }
  for (; i < parts.size(); ++i) {
    std::string name = parts[i];
    const bool item = name.size() > 2 && name.compare(name.size() - 2, 2, "[]") == 0;
    if (item) name.resize(name.size() - 2);
    if (!n[name]) n[name] = YAML::Node(YAML::NodeType::Map);
    YAML::Node next = n[name];
    n.reset(next);
    if (item) {
      YAML::Node first = n[0];
      n.reset(first);
    }
  }
  return n;
}

// The problems of the base scene with `entries` (a flow mapping) merged into the holder of `path`.
// `model`, when given, is the base scene's organ.model (for the keys only one model uses).
std::vector<SceneProblem> problems_with(const std::string& path, const std::string& entries, const std::string& file,
                                       const std::string& model = "") {
  const fs::path dir = test::scratch_dir("scene_reference");
  YAML::Node root = YAML::Load(kBaseScene);
  if (!model.empty()) root["organ"]["model"] = model;
  // The endoscope's keys go into an endoscope, not the base scene's framing camera.
  for (const char* scope : {"type", "port", "look_at", "depth", "angle_deg", "roll_deg", "script"})
    if (path.rfind(std::string("render.camera.") + scope, 0) == 0)
      root["render"]["camera"] =
          YAML::Load("{type: endoscope, port: [0, -0.12, 0.12], look_at: [0, 0, 0.02], script: [{t: 1}]}");
  // The keys of `organs` go into a scene of several organs: the base organ as the list's first,
  // named (an example of the whole list replaces it).
  if (path.rfind("organs", 0) == 0) {
    YAML::Node organ = root["organ"];
    organ["name"] = "base";
    root["organs"].push_back(organ);
    root.remove("organ");
  }
  // The keys of `attachments` go into a scene of two organs (gallbladder and liver) with
  // constraint contact, which ties need; those of its items into an attachment between them.
  if (path.rfind("attachments", 0) == 0) {
    YAML::Node first = YAML::Clone(root["organ"]), second = YAML::Clone(root["organ"]);
    first["name"] = "gallbladder";
    second["name"] = "liver";
    second["translate"] = YAML::Load("[0.5, 0, 0]");
    root["organs"].push_back(first);
    root["organs"].push_back(second);
    root.remove("organ");
    root["simulation"].remove("contact");
    root["attachments"] = YAML::Load("[{between: [gallbladder, liver], within: 0.004}]");
  }
  YAML::Node into = path.rfind("organs[].", 0) == 0        ? YAML::Node(root["organs"][0])
                    : path.rfind("attachments[].", 0) == 0 ? YAML::Node(root["attachments"][0])
                                                           : holder(root, path);
  const YAML::Node add = YAML::Load("{" + entries + "}");
  for (auto it = add.begin(); it != add.end(); ++it) into[it->first.Scalar()] = it->second;
  // A keyframe placed on the surface gives no tip, and one aligned with the surface no axis:
  // the base keyframe's go.
  if (path.rfind("instruments[].script[].", 0) == 0) {
    YAML::Node key = root["instruments"][0]["script"][0];
    if (path.find("on_surface") != std::string::npos || add["on_surface"]) key.remove("tip");
    if (add["align"]) key.remove("axis");
    // Port coordinates place the tip from the instrument's port.
    if (add["pan_deg"] || add["tilt_deg"]) {
      root["instruments"][0]["port"] = YAML::Load("[0.09, -0.08, 0.14]");
      key.remove("tip");
    }
  }
  // Through a port, the axis runs from the port through the tip: the keyframes give none.
  if (root["instruments"][0]["port"]) root["instruments"][0]["script"][0].remove("axis");
  // The camera's focus is for the automatic camera: the base camera's eye and target go.
  if (add["focus"]) {
    into.remove("eye");
    into.remove("target");
  }
  YAML::Emitter e;
  e << root;
  fs::create_directories(dir / "scenes");
  const fs::path scene = dir / "scenes" / file;
  std::ofstream(scene) << e.c_str() << "\n";
  return load_scene(scene.string()).problems;
}

std::string text_of(const std::vector<SceneProblem>& problems) {
  std::string s;
  for (const SceneProblem& p : problems) s += p.text() + "\n";
  return s;
}

// The mesh files the base scene and the examples name, in the scratch folder's meshes/.
void make_meshes() {
  const fs::path meshes = test::scratch_dir("scene_reference") / "meshes";
  fs::create_directories(meshes);
  std::set<std::string> names = {"liver_L4.obj", "probe.obj"};
  const std::string folder = "../meshes/";
  for (const SceneKey& k : kSceneKeys) {
    const std::string example = k.example;
    for (size_t at = example.find(folder); at != std::string::npos; at = example.find(folder, at + 1)) {
      size_t e = at + folder.size();
      while (e < example.size() && (std::isalnum(static_cast<unsigned char>(example[e])) || example[e] == '_')) ++e;
      if (example.compare(e, 4, ".obj") == 0) names.insert(example.substr(at + folder.size(), e + 4 - at - folder.size()));
    }
  }
  for (const std::string& name : names)
    fs::copy_file(fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj", meshes / name,
                  fs::copy_options::overwrite_existing);
}

TEST(SceneReference, BaseSceneLoadsWithoutProblems) {
  make_meshes();
  const std::vector<SceneProblem> p = problems_with("name", "name: base", "base.yaml");
  EXPECT_TRUE(p.empty()) << text_of(p);
}

TEST(SceneReference, EveryKeysExampleLoadsWithoutProblems) {
  make_meshes();
  int i = 0;
  for (const SceneKey& k : kSceneKeys) {
    if (k.type == KeyType::region) continue;
    SCOPED_TRACE(k.path);
    ASSERT_NE(std::string(k.example), "") << k.path << " has no example";
    const std::string name = split(k.path).back();
    const YAML::Node example = YAML::Load(std::string("{") + k.example + "}");
    EXPECT_TRUE(example[name.substr(0, name.find('['))]) << "the example of " << k.path << " does not set it: " << k.example;
    // A key only some models use is warned about under the others (ignored by organ.model):
    // its example is loaded with the default model when that uses it, else with the first that does.
    // An example of penalty contact is loaded with a model that takes it.
    std::string model;
    if (!organ_model(kDefaultOrganModel).uses(k.path))
      for (const OrganModel& m : organ_models())
        if (model.empty() && m.uses(k.path)) model = m.name();
    if (std::string(k.example).find("method: penalty") != std::string::npos && !organ_model(kDefaultOrganModel).penalty_contact)
      model = organ_model_names(&OrganModel::penalty_contact).at(0);
    const std::vector<SceneProblem> p = problems_with(k.path, k.example, "example_" + std::to_string(i++) + ".yaml", model);
    EXPECT_TRUE(p.empty()) << k.path << ": " << k.example << "\n" << text_of(p);
  }
}

TEST(SceneReference, EveryListedValueIsKnownToTheReader) {
  make_meshes();
  int i = 0;
  for (const SceneKey& k : kSceneKeys) {
    if (!k.values) continue;
    const std::string name = split(k.path).back();
    for (const std::string& v : k.values()) {
      const std::string entry = name + ": " + (k.type == KeyType::choice_list ? "[" + v + "]" : v);
      const std::vector<SceneProblem> p = problems_with(k.path, entry, "value_" + std::to_string(i++) + ".yaml");
      const std::string all = text_of(p);
      EXPECT_EQ(all.find("unknown"), std::string::npos) << k.path << ": " << v << "\n" << all;
    }
  }
}

TEST(SceneReference, ReaderChecksKeysAgainstTheTable) {
  make_meshes();
  const std::vector<SceneProblem> p = problems_with("simulation.frames", "frmes: 3", "typo.yaml");
  ASSERT_EQ(p.size(), 1u) << text_of(p);
  EXPECT_TRUE(p[0].warning);
  EXPECT_NE(p[0].message.find("(did you mean 'frames'?); known keys: frames, dt, effects, solver, gravity, "
                              "volume_constraint, contact"),
            std::string::npos)
      << p[0].message;
  EXPECT_EQ(scene_key_names("instruments[].shape", "box"), (std::vector<std::string>{"type", "size", "rounding"}));
  EXPECT_EQ(scene_key_names("instruments[].shape", "capsule"), (std::vector<std::string>{"type"}));
}

TEST(SceneReference, DefaultsAreWrittenAsScenesWriteThem) {
  EXPECT_EQ(yaml_number(1e-8), "1e-8");
  EXPECT_EQ(yaml_number(1e12), "1e12");
  EXPECT_EQ(yaml_number(20000), "20000");
  EXPECT_EQ(yaml_number(1.0 / 30.0), "0.0333333");
  EXPECT_EQ(yaml_number(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(yaml_vector(vdm::Vec3(0, 0, -9.81)), "[0, 0, -9.81]");
}

}  // namespace
}  // namespace vdmsim
