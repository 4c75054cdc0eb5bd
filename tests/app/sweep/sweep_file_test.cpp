// Sweep files: the grid, zip and cases forms expanded into runs; every key checked against the
// scene's keys and the base scene, with the sweep file's line and column and the closest key;
// each run's scene complete and runnable from anywhere (file paths absolute).
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "app/sweep/sweep_file.hpp"
#include "app/sweep/sweep_plan.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kBase = std::string(VDMSIM_SOURCE_DIR) + "/tests/golden/scenes/probe_small.yaml";

// Writes a sweep file (its base the golden probe scene) and reads it.
bool read(const std::string& name, const std::string& body, vdmsim::SweepFile& sweep,
          std::vector<vdmsim::SceneProblem>& problems) {
  const fs::path file = vdmsim::test::scratch_dir("sweep_file") / name;
  std::ofstream(file) << "base: " << kBase << "\n" << body;
  return vdmsim::read_sweep_file(file.string(), sweep, problems);
}

std::string all_text(const std::vector<vdmsim::SceneProblem>& problems) {
  std::string s;
  for (const auto& p : problems) s += p.text() + "\n";
  return s;
}

}  // namespace

TEST(SweepFile, GridIsEveryCombinationWithTheFirstKeySlowest) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(read("grid.yaml",
                   "vary:\n  organ.material.young_modulus: [10000, 20000, 40000]\n  instruments[0].radius: [0.003, 0.005]\n",
                   sweep, problems))
      << all_text(problems);
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), 6u);
  EXPECT_EQ(plan.columns, (std::vector<std::string>{"organ.material.young_modulus", "instruments[0].radius"}));
  EXPECT_EQ(plan.runs[0].folder, "000_young_modulus-10000_radius-0.003");
  EXPECT_EQ(plan.runs[1].values, (std::vector<std::string>{"10000", "0.005"}));
  EXPECT_EQ(plan.runs[5].values, (std::vector<std::string>{"40000", "0.005"}));
  // The run's scene holds its values, and the base's other keys.
  const YAML::Node scene = YAML::Load(plan.runs[4].scene_text);
  EXPECT_EQ(scene["organ"]["material"]["young_modulus"].as<double>(), 40000);
  EXPECT_EQ(scene["instruments"][0]["radius"].as<double>(), 0.003);
  EXPECT_EQ(scene["organ"]["material"]["poisson_ratio"].as<double>(), 0.45);
  EXPECT_EQ(scene["simulation"]["frames"].as<int>(), 4);
}

TEST(SweepFile, RunScenesNameTheirMeshAbsolutelySoTheyRunFromTheirOwnFolder) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(read("mesh.yaml", "cases:\n  - {organ.material.density: 1000}\n  - {organ.mesh: ../meshes/x.obj}\n", sweep,
                   problems))
      << all_text(problems);
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), 2u);
  // The base's relative mesh path resolved against the base; a value's against the sweep file.
  const std::string base_mesh = YAML::Load(plan.runs[0].scene_text)["organ"]["mesh"].as<std::string>();
  EXPECT_EQ(base_mesh, (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").lexically_normal().string());
  const std::string value_mesh = YAML::Load(plan.runs[1].scene_text)["organ"]["mesh"].as<std::string>();
  EXPECT_EQ(value_mesh, (vdmsim::test::scratch_dir("sweep_file").parent_path() / "meshes/x.obj").lexically_normal().string());
  EXPECT_EQ(plan.runs[0].values, (std::vector<std::string>{"1000", ""}));  // a case leaves the other key
}

TEST(SweepFile, ZipTakesListsTogether) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(read("zip.yaml",
                   "vary:\n  organ.material.density: [1000, 1100]\n"
                   "zip:\n  organ.material.young_modulus: [10000, 20000, 40000]\n  instruments[0].radius: [0.003, 0.004, 0.005]\n",
                   sweep, problems))
      << all_text(problems);
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), 6u);  // 2 densities x 3 zipped pairs
  EXPECT_EQ(plan.runs[2].values, (std::vector<std::string>{"1000", "40000", "0.005"}));
  EXPECT_EQ(plan.runs[3].values, (std::vector<std::string>{"1100", "10000", "0.003"}));
}

TEST(SweepFile, SeveralZipGroupsAreAxesOfTheGridWithVary) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(read("zips.yaml",
                   "vary:\n  organ.material.density: [1000, 1100]\n"
                   "zip:\n"
                   "  - organ.material.young_modulus: [10000, 40000]\n"
                   "    instruments[0].radius: [0.003, 0.005]\n"
                   "  - organ.material.connectivity_modulus: [1000, 2000, 3000]\n"
                   "    organ.material.damping: [0.1, 0.2, 0.3]\n",
                   sweep, problems))
      << all_text(problems);
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), 12u);  // 2 densities x 2 pairs x 3 pairs
  EXPECT_EQ(plan.columns, (std::vector<std::string>{"organ.material.density", "organ.material.young_modulus",
                                                    "instruments[0].radius", "organ.material.connectivity_modulus",
                                                    "organ.material.damping"}));
  // vary slowest, then the first group, the last group fastest; each group's values together.
  EXPECT_EQ(plan.runs[0].values, (std::vector<std::string>{"1000", "10000", "0.003", "1000", "0.1"}));
  EXPECT_EQ(plan.runs[1].values, (std::vector<std::string>{"1000", "10000", "0.003", "2000", "0.2"}));
  EXPECT_EQ(plan.runs[4].values, (std::vector<std::string>{"1000", "40000", "0.005", "2000", "0.2"}));
  EXPECT_EQ(plan.runs[11].values, (std::vector<std::string>{"1100", "40000", "0.005", "3000", "0.3"}));
  const YAML::Node scene = YAML::Load(plan.runs[4].scene_text);
  EXPECT_EQ(scene["organ"]["material"]["young_modulus"].as<double>(), 40000);
  EXPECT_EQ(scene["instruments"][0]["radius"].as<double>(), 0.005);
  EXPECT_EQ(scene["organ"]["material"]["damping"].as<double>(), 0.2);

  // A group's lists of different lengths, a key in two groups, groups that are not mappings.
  ASSERT_FALSE(read("zips_bad.yaml",
                    "zip:\n"
                    "  - organ.material.young_modulus: [10000, 40000]\n"
                    "  - organ.material.connectivity_modulus: [1000, 2000, 3000]\n"
                    "    organ.material.damping: [0.1, 0.2]\n"
                    "  - organ.material.young_modulus: [1, 2]\n"
                    "  - [organ.material.density]\n",
                    sweep, problems));
  const std::string said = all_text(problems);
  EXPECT_NE(said.find("zips_bad.yaml:5:29: zip[1].organ.material.damping: zip: lists go together, so each has as many "
                      "values as the first (3 at "),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("zips_bad.yaml:6:5: zip[2].organ.material.young_modulus: 'organ.material.young_modulus' is varied twice"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("zips_bad.yaml:7:5: zip[3]: expected a mapping of scene keys to lists of values"), std::string::npos)
      << said;
  problems.clear();
  ASSERT_FALSE(read("zips_empty.yaml", "zip: []\n", sweep, problems));
  EXPECT_NE(all_text(problems).find("zip: expected a mapping of scene keys to lists (one group), or a list of such mappings"),
            std::string::npos)
      << all_text(problems);
}

TEST(SweepFile, QuotedValuesStayQuotedInTheRunsScene) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(read("quoted.yaml", "cases:\n  - {name: \"0.5\"}\n  - {name: 'yes'}\n  - {name: 0.5}\n", sweep, problems))
      << all_text(problems);
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), 3u);
  // Written quoted, read back as the strings they were; the unquoted one stays plain.
  EXPECT_NE(plan.runs[0].scene_text.find("name: \"0.5\"\n"), std::string::npos) << plan.runs[0].scene_text;
  EXPECT_NE(plan.runs[1].scene_text.find("name: \"yes\"\n"), std::string::npos) << plan.runs[1].scene_text;
  EXPECT_NE(plan.runs[2].scene_text.find("name: 0.5\n"), std::string::npos) << plan.runs[2].scene_text;
  const YAML::Node quoted = YAML::Load(plan.runs[0].scene_text), plain = YAML::Load(plan.runs[2].scene_text);
  EXPECT_EQ(quoted["name"].Tag(), "!");  // a quoted scalar: a string, never a number
  EXPECT_EQ(plain["name"].Tag(), "?");
  // The base's own values keep their form (numbers plain, flow lists in flow style).
  EXPECT_NE(plan.runs[0].scene_text.find("young_modulus: 3000"), std::string::npos) << plan.runs[0].scene_text;
  EXPECT_EQ(quoted["organ"]["material"]["young_modulus"].Tag(), "?");
  // The run's scene is a scene like any: it loads, with the quoted name.
  const fs::path file = vdmsim::test::scratch_dir("sweep_file") / "quoted_run.yaml";
  std::ofstream(file) << plan.runs[1].scene_text;
  const vdmsim::SceneLoadResult loaded = vdmsim::load_scene(file.string());
  ASSERT_TRUE(loaded.ok()) << all_text(loaded.problems);
  EXPECT_EQ(loaded.scene.name, "yes");
}

// Issue 46: a value with a line break (or any other YAML syntax) stays a value. The run's
// scene.yaml carries it in its header comment and as the key's value; neither may add a key
// (here: render:, which the base lacks, so that the run would render).
TEST(SweepFile, NoValueBecomesYamlStructureInTheRunsScene) {
  const fs::path dir = vdmsim::test::scratch_dir("sweep_file");
  const std::string base = (dir / "no_render_base.yaml").string();
  std::ofstream(base) << "name: plain\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                      << "/assets/meshes/liver_L4.obj\nsimulation: {frames: 2, dt: 0.1}\n";
  const std::vector<std::string> values = {
      "trial\nrender: {width: 64, height: 48, views: [shaded]}",
      "trial\r\nrender: {width: 64}", "trial\rrender: {width: 64}", "a: b", "x # y", "- item", "[1", "{a", "&anchor",
      "*alias", "!tag", "'q", "\"d", "...", "---", "% directive", "@at", "`tick", "|", ">", "? q", " lead", "trail ",
      "tab\there", "null", "~", "true", "line\u2028separator", "next\xC2\x85line", "bell\a"};
  // Each value written double-quoted, with YAML's escapes for the line breaks and controls.
  auto quoted = [](const std::string& v) {
    std::string q = "\"";
    for (size_t k = 0; k < v.size(); ++k) {
      const unsigned char c = static_cast<unsigned char>(v[k]);
      char hex[8];
      if (v.compare(k, 3, "\u2028") == 0) q += "\\u2028", k += 2;
      else if (v.compare(k, 2, "\xC2\x85") == 0) q += "\\x85", k += 1;
      else if (c == '"' || c == '\\') q += std::string("\\") + char(c);
      else if (c < 0x20) std::snprintf(hex, sizeof hex, "\\x%02x", c), q += hex;
      else q += char(c);
    }
    return q + "\"";
  };
  std::string body = "cases:\n";
  for (const std::string& v : values) body += "  - {name: " + quoted(v) + "}\n";
  const fs::path file = dir / "structure.yaml";
  std::ofstream(file) << "base: " << base << "\n" << body;
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::read_sweep_file(file.string(), sweep, problems)) << all_text(problems) << body;
  const vdmsim::SweepPlan plan = vdmsim::plan_sweep(sweep);
  ASSERT_EQ(plan.runs.size(), values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const std::string& text = plan.runs[i].scene_text;
    // The header is one comment line; the scene below it has the base's keys only.
    const std::string header = text.substr(0, text.find('\n'));
    EXPECT_EQ(header.rfind("# vdmsim sweep ", 0), 0u) << text;
    EXPECT_EQ(header.find('\r'), std::string::npos) << text;
    const fs::path run = dir / ("structure_run_" + std::to_string(i) + ".yaml");
    std::ofstream(run, std::ios::binary) << text;
    const vdmsim::SceneLoadResult loaded = vdmsim::load_scene(run.string());
    ASSERT_TRUE(loaded.ok()) << all_text(loaded.problems) << text;
    EXPECT_EQ(loaded.scene.name, values[i]) << text;
    EXPECT_FALSE(loaded.scene.has_render) << text;
    const YAML::Node scene = YAML::Load(text);
    EXPECT_EQ(scene.size(), 3u) << text;  // name, organ, simulation
  }
}

TEST(SweepFile, UnknownKeyNamesLineColumnAndTheClosestKey) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_FALSE(read("typo.yaml", "vary:\n  organ.material.bulk_modulos: [1, 2]\n", sweep, problems));
  const std::string said = all_text(problems);
  EXPECT_NE(said.find("typo.yaml:3:3: vary.organ.material.bulk_modulos: unknown scene key 'bulk_modulos' in organ.material "
                      "(did you mean 'bulk_modulus'?)"),
            std::string::npos)
      << said;
}

TEST(SweepFile, EachKindOfBadKeyOrValueHasItsOwnMessage) {
  struct Case {
    std::string body, expected;
  } cases[] = {
      {"vary:\n  instruments[3].radius: [0.003]\n", "bad.yaml:3:3: vary.instruments[3].radius: instruments[3]: the base scene's instruments has 1 item"},
      {"vary:\n  instruments.radius: [0.003]\n", "instruments is a list: name one item, e.g. instruments[0]"},
      {"vary:\n  organ.material.density.x: [1]\n", "density is a value: it has no keys below it"},
      {"vary:\n  organ.material[0]: [1]\n", "material is a mapping, not a list"},
      {"vary:\n  organ..mesh: [a.obj]\n", "'organ..mesh' is not a scene key path"},
      {"vary:\n  organ.material.density: 1000\n", "bad.yaml:3:27: vary.organ.material.density: expected a non-empty list of values"},
      {"vary:\n  organ.material.density: []\n", "got an empty list"},
      {"zip:\n  organ.material.density: [1, 2]\n  instruments[0].radius: [0.1]\n", "bad.yaml:4:26: zip.instruments[0].radius: zip: lists go together, so each has as many values as the first (2 at "},
      {"vary:\n  organ.material.density: [1]\ncases:\n  - {organ.material.density: 1}\n", "give either cases: or vary:/zip:"},
      {"vary:\n  organ.material.density: [1]\n  organ.material.density: [2]\n", "bad.yaml:4:3: vary.organ.material.density: 'organ.material.density' is varied twice (first at "},
      {"varry:\n  organ.material.density: [1]\n", "bad.yaml:2:1: varry: unknown key 'varry' (did you mean 'vary'?)"},
      {"cases: [3]\n", "bad.yaml:2:9: cases[0]: expected a mapping of scene keys to values"},
      {"cases: [{}]\n", "bad.yaml:2:9: cases[0]: an empty mapping: give at least one scene key and its value"},
      {"", "nothing varies"},
      {"vary: {}\n", "bad.yaml:2:7: vary: nothing varies: vary: is empty; give vary: (a grid)"},
      {"zip: {}\n", "bad.yaml:2:6: zip: nothing varies: zip: is empty; give vary: (a grid)"},
  };
  for (const Case& c : cases) {
    vdmsim::SweepFile sweep;
    std::vector<vdmsim::SceneProblem> problems;
    EXPECT_FALSE(read("bad.yaml", c.body, sweep, problems)) << c.body;
    const std::string said = all_text(problems);
    EXPECT_NE(said.find(c.expected), std::string::npos) << "sweep:\n" << c.body << "said:\n" << said;
  }
}

TEST(SweepFile, MissingBaseAndBrokenYamlAreNamed) {
  const fs::path dir = vdmsim::test::scratch_dir("sweep_file");
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  std::ofstream(dir / "nobase.yaml") << "base: nowhere.yaml\nvary: {organ.material.density: [1]}\n";
  EXPECT_FALSE(vdmsim::read_sweep_file((dir / "nobase.yaml").string(), sweep, problems));
  EXPECT_NE(all_text(problems).find("nobase.yaml:1:7: base: no such scene file"), std::string::npos) << all_text(problems);
  // A folder, or a device that never ends, is no scene file either, and said so.
  for (const std::string& base : {dir.string(), std::string("/dev/zero")}) {
    problems.clear();
    std::ofstream(dir / "oddbase.yaml") << "base: " << base << "\nvary: {organ.material.density: [1]}\n";
    EXPECT_FALSE(vdmsim::read_sweep_file((dir / "oddbase.yaml").string(), sweep, problems));
    const std::string said = all_text(problems);
    EXPECT_NE(said.find("oddbase.yaml:1:7: base: " + base + (base == "/dev/zero" ? ": not a regular file" : ": a folder")),
              std::string::npos)
        << said;
    EXPECT_EQ(said.find("no such scene file"), std::string::npos) << said;
  }
  problems.clear();
  std::ofstream(dir / "broken.yaml") << "base: [\n";
  EXPECT_FALSE(vdmsim::read_sweep_file((dir / "broken.yaml").string(), sweep, problems));
  EXPECT_NE(all_text(problems).find("broken.yaml:2:1: sweep: not valid YAML"), std::string::npos) << all_text(problems);
}

// yaml-cpp's LoadAll loops forever on some inputs (fuzz_sweep found this one): the sweep reader
// counts documents itself and parses one, as the scene reader does.
TEST(SweepFile, AnInputThatHungTheYamlLoaderIsReadAtOnceAndTwoDocumentsAreNamed) {
  const fs::path dir = vdmsim::test::scratch_dir("sweep_file");
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  std::ofstream(dir / "hang.yaml", std::ios::binary) << ",as\x96: .\nvary: {organ.material.density: [1]}\n";
  EXPECT_FALSE(vdmsim::read_sweep_file((dir / "hang.yaml").string(), sweep, problems));
  EXPECT_NE(all_text(problems).find("hang.yaml:"), std::string::npos) << all_text(problems);
  problems.clear();
  std::ofstream(dir / "two.yaml") << "base: " << kBase << "\nvary: {organ.material.density: [1]}\n---\nbase: x\n";
  EXPECT_FALSE(vdmsim::read_sweep_file((dir / "two.yaml").string(), sweep, problems));
  EXPECT_NE(all_text(problems).find("two.yaml:3:1: sweep: the file holds several YAML documents"), std::string::npos)
      << all_text(problems);
}

TEST(SweepCli, BadSweepFileExitsTwoNamingFileLineColumnAndField) {
  const fs::path file = vdmsim::test::scratch_dir("sweep_file") / "cli_bad.yaml";
  std::ofstream(file) << "base: " << kBase << "\nvary:\n  instruments[0].radus: [0.003, 0.005]\n";
  const fs::path out = vdmsim::test::scratch_dir("sweep_file") / "cli_bad_out";
  const vdmsim::test::CliResult r = vdmsim::test::run_cli(VDMSIM_BINARY, "sweep " + file.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cli_bad.yaml:3:3: vary.instruments[0].radus: unknown scene key 'radus' in instruments[0] (did you "
                          "mean 'radius'?)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out / "runs")) << "nothing is written for a bad sweep file";
}

TEST(SweepFile, TheExampleSweepIsValid) {
  vdmsim::SweepFile sweep;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::read_sweep_file(std::string(VDMSIM_SOURCE_DIR) + "/assets/sweeps/probe_stiffness.yaml", sweep, problems))
      << all_text(problems);
  EXPECT_EQ(vdmsim::plan_sweep(sweep).runs.size(), 6u);
}
