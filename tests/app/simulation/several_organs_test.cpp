// Scenes with several organs (`organs:`): each organ read with its own name and keys (problems
// named by the organ's place in the list), prepared and simulated with its own model, state and
// contact against every instrument, and written out organ by organ (metrics.csv columns,
// run.json's organs, --export-mesh's folders). An organ that no instrument and no other organ
// reaches moves exactly as it does alone: the scene's other organs change nothing of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/check/scene_sanity.hpp"
#include "app/run/scene_run.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "support/run_outputs.hpp"
#include "support/scene_text.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

const std::string kLiver = std::string(VDMSIM_SOURCE_DIR) + "/assets/meshes/liver_L4.obj";

// The liver with its base held, moved `dx` along x, as an item of `organs:` named `name`.
std::string organ_item(const std::string& name, double dx) {
  std::ostringstream s;
  s << "  - name: " << name << "\n    mesh: " << kLiver << "\n    translate: [" << dx << ", 0, 0]\n"
    << "    material: {young_modulus: 3000, poisson_ratio: 0.45}\n"
    << "    fixed: [{box: {min: [" << dx - 0.3 << ", -0.2, -0.2], max: [" << dx + 0.3 << ", 0.2, -0.03]}}]\n";
  return s.str();
}

// The same liver as the scene's only organ.
std::string organ_alone(double dx) {
  std::ostringstream s;
  s << "organ:\n    mesh: " << kLiver << "\n    translate: [" << dx << ", 0, 0]\n"
    << "    material: {young_modulus: 3000, poisson_ratio: 0.45}\n"
    << "    fixed: [{box: {min: [" << dx - 0.3 << ", -0.2, -0.2], max: [" << dx + 0.3 << ", 0.2, -0.03]}}]\n";
  return s.str();
}

constexpr double kApart = 0.5;  // m between the two livers: far more than either's size (0.17 m)

// Two probes, one pressing each liver 12 mm; 6 frames.
const std::string kRest =
    "simulation: {frames: 6, dt: 0.1, effects: [contact, stress]}\n"
    "instruments:\n"
    "  - {type: probe, radius: 0.006, script: [{t: 0, tip: [0.035, 0, 0.062], axis: [0, 0, -1]}, {t: 0.5, tip: [0.035, 0, 0.05]}]}\n"
    "  - {type: probe, radius: 0.006, script: [{t: 0, tip: [0.535, 0, 0.062], axis: [0, 0, -1]}, {t: 0.5, tip: [0.535, 0, 0.045]}]}\n";

std::string two_livers() { return "name: two_livers\norgans:\n" + organ_item("left", 0) + organ_item("right", kApart) + kRest; }

std::vector<SceneProblem> problems_of(const std::string& text) {
  const fs::path p = test::test_output_dir("several_organs") / "scene.yaml";
  std::ofstream(p) << text;
  return load_scene(p.string()).problems;
}

bool has_problem(const std::vector<SceneProblem>& problems, const std::string& field, const std::string& words,
                 bool warning = false) {
  for (const SceneProblem& p : problems)
    if (p.field == field && p.message.find(words) != std::string::npos && p.warning == warning) return true;
  return false;
}

std::string text_of(const std::vector<SceneProblem>& problems) {
  std::string s;
  for (const SceneProblem& p : problems) s += p.text() + "\n";
  return s;
}

TEST(SeveralOrgans, EachOrganIsReadAndPreparedWithItsNameAndKeys) {
  const PreparedScene ps = test::prepare_scene_text("several_organs", two_livers());
  ASSERT_EQ(ps.scene.organs.size(), 2u);
  EXPECT_EQ(ps.scene.organs[0].name, "left");
  EXPECT_EQ(ps.scene.organs[1].name, "right");
  EXPECT_EQ(ps.scene.organs[1].field, "organs[1]");
  EXPECT_EQ(ps.scene.organs[1].translate.x(), kApart);
  ASSERT_EQ(ps.organs.size(), 2u);
  const int n = ps.organs[0].model.n;
  EXPECT_EQ(ps.organs[1].model.n, n);
  // The scene's surface holds both, the second's nodes after the first's, where it was placed.
  EXPECT_EQ(ps.surface.node_count(), 2 * n);
  EXPECT_EQ(ps.surface.triangle_count(), 2 * ps.organs[0].model.rest.triangle_count());
  ASSERT_EQ(ps.node_offset, (std::vector<int>{0, n, 2 * n}));
  EXPECT_EQ((ps.surface.positions.row(n + 7) - ps.organs[1].model.rest.positions.row(7)).norm(), 0.0);
  EXPECT_EQ(ps.surface.triangles(ps.organs[0].model.rest.triangle_count(), 0),
            ps.organs[1].model.rest.triangles(0, 0) + n);
  EXPECT_NEAR(ps.organs[1].model.rest.positions.col(0).mean() - ps.organs[0].model.rest.positions.col(0).mean(), kApart,
              1e-12);
}

TEST(SeveralOrgans, ProblemsNameTheOrganInTheList) {
  const std::string head = "name: x\norgans:\n";
  // Names: given, unique, words only.
  EXPECT_TRUE(has_problem(problems_of(head + organ_item("a", 0) + organ_item("a", kApart) + kRest), "organs[1].name",
                          "is the name of organs[0] already"));
  EXPECT_TRUE(has_problem(problems_of(head + organ_item("a b", 0) + kRest), "organs[0].name", "letters, digits"));
  std::string unnamed = organ_item("a", 0);
  unnamed.replace(unnamed.find("- name: a\n    "), 14, "- ");
  EXPECT_TRUE(has_problem(problems_of(head + unnamed + kRest), "organs[0].name", "missing")) << text_of(problems_of(head + unnamed + kRest));
  // One form or the other, and a list of at least one.
  EXPECT_TRUE(has_problem(problems_of("name: x\n" + organ_alone(0) + "organs:\n" + organ_item("a", kApart) + kRest),
                          "organs", "not both"));
  EXPECT_TRUE(has_problem(problems_of("name: x\norgans: []\n" + kRest), "organs", "at least one"));
  // An organ's own keys are named by its place: a value out of range, an unknown key, a key its
  // model ignores.
  std::string bad = organ_item("b", kApart);
  bad.replace(bad.find("young_modulus: 3000"), 19, "young_modulus: -1");
  bad += "    colour: red\n    tet_size: 0.01\n";
  const std::vector<SceneProblem> p = problems_of(head + organ_item("a", 0) + bad + kRest);
  EXPECT_TRUE(has_problem(p, "organs[1].material.young_modulus", "out of range")) << text_of(p);
  EXPECT_TRUE(has_problem(p, "organs[1].colour", "unknown key", true)) << text_of(p);
  EXPECT_TRUE(has_problem(p, "organs[1].tet_size", "ignored by organs[1].model vdm_core", true)) << text_of(p);
}

TEST(SeveralOrgans, AnOrganNoOtherReachesMovesExactlyAsItDoesAlone) {
  const PreparedScene both = test::prepare_scene_text("several_organs", two_livers());
  const PreparedScene left = test::prepare_scene_text("several_organs", "name: left\n" + organ_alone(0) + kRest);
  const PreparedScene right = test::prepare_scene_text("several_organs", "name: right\n" + organ_alone(kApart) + kRest);
  SceneSimulation sim(both);
  SceneSimulation alone[2] = {SceneSimulation(left), SceneSimulation(right)};
  for (int f = 0; f < both.scene.frames; ++f) {
    sim.advance(f);
    for (SceneSimulation& a : alone) a.advance(f);
    ASSERT_EQ(sim.unsound(), "") << "frame " << f;
    for (size_t i = 0; i < 2; ++i) {
      // Bit for bit: the same solves on the same numbers.
      EXPECT_TRUE(sim.state(i).u == alone[i].state().u) << "organ " << i << ", frame " << f;
      EXPECT_EQ(sim.state(i).pressure, alone[i].state().pressure);
      // Each organ keeps its own volume.
      EXPECT_LT(std::abs(sim.state(i).volume_rel_error), 1e-9);
      // The positions of the whole scene are the organs' in turn.
      EXPECT_TRUE(sim.positions().middleRows(both.node_offset[i], sim.state(i).x.rows()) == sim.state(i).x);
    }
  }
  // Each probe pressed its own liver only: organ i's force on probe j, and the scene's sum.
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_GT(sim.instrument_forces(i)[i].norm(), 0.05) << "organ " << i;
    EXPECT_EQ(sim.instrument_forces(i)[1 - i].norm(), 0.0) << "organ " << i;
    EXPECT_TRUE(sim.instrument_forces()[i] == sim.instrument_forces(i)[i]);
  }
  EXPECT_GT(sim.instrument_forces()[1].norm(), sim.instrument_forces()[0].norm());  // pressed deeper
  EXPECT_EQ(sim.contact_report().nodes, sim.contact_report(0).nodes + sim.contact_report(1).nodes);
}

TEST(SeveralOrgans, RunsWriteEachOrgansColumnsEntryAndMeshes) {
  const fs::path dir = test::test_output_dir("several_organs") / "run";
  fs::remove_all(dir);
  PreparedScene ps = test::prepare_scene_text("several_organs", two_livers());
  RunOptions opt;
  opt.out_dir = dir.string();
  opt.export_mesh = true;
  std::ostringstream out, err;
  ASSERT_EQ(run_scene(ps, opt, out, err, false), 0) << err.str();
  // metrics.csv: the scene's columns, then each organ's.
  std::ifstream csv(dir / "metrics.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* organ : {"left", "right"})
    for (const char* column : {"_volume,", "_volume_rel_error,", "_pressure_pa,", "_contact_nodes,", "_contact_force_n,"})
      EXPECT_NE(header.find(std::string(organ) + column), std::string::npos) << organ << column << " in " << header;
  std::string row;
  int rows = 0;
  while (std::getline(csv, row)) {
    ++rows;
    EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ',')) << row;
  }
  EXPECT_EQ(rows, ps.scene.frames);
  // run.json: every organ with its nodes, model, material and volume error.
  const std::string js = test::read_file(dir / "run.json");
  EXPECT_NE(js.find("\"organs\": [\n    {\"name\": \"left\", \"nodes\": " + std::to_string(ps.organs[0].model.n) +
                    ", \"model\": \"vdm_core\", \"material\": {\"young_modulus_pa\": 3000"),
            std::string::npos)
      << js;
  EXPECT_NE(js.find("{\"name\": \"right\""), std::string::npos) << js;
  EXPECT_NE(js.find("\"nodes\": " + std::to_string(ps.surface.node_count())), std::string::npos) << js;
  // --export-mesh: a folder and a .pvd per organ, each frame in each.
  for (const char* organ : {"left", "right"}) {
    EXPECT_TRUE(fs::exists(dir / (std::string(organ) + ".pvd"))) << organ;
    for (int f = 0; f < ps.scene.frames; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.vtu", f);
      EXPECT_TRUE(fs::exists(dir / "mesh" / organ / name)) << organ << " " << name;
    }
  }
  EXPECT_FALSE(fs::exists(dir / "mesh.pvd"));
}

// Contact between organs is not simulated: organs placed into each other are an error of
// `check`, and a run of them stops at its first frame, naming both and how deep.
TEST(SeveralOrgans, OrgansInsideEachOtherAreReportedAndStopTheRun) {
  const PreparedScene ps = test::prepare_scene_text(
      "several_organs", "name: x\norgans:\n" + organ_item("left", 0) + organ_item("right", 0.1) + kRest);
  const SanityReport report = scene_sanity(ps);
  bool reported = false;
  for (const SceneProblem& p : report.problems)
    reported = reported || (!p.warning && p.field == "organs[1]" && p.message.find("overlap at rest") != std::string::npos);
  EXPECT_TRUE(reported) << text_of(report.problems);
  SceneSimulation sim(ps);
  sim.advance(0);
  const std::string why = sim.unsound();
  EXPECT_NE(why.find("organs left and right pass into each other"), std::string::npos) << why;
  EXPECT_NE(why.find("mm inside"), std::string::npos) << why;
  // Apart, nothing is reported.
  const PreparedScene apart = test::prepare_scene_text("several_organs", two_livers());
  for (const SceneProblem& p : scene_sanity(apart).problems) EXPECT_EQ(p.message.find("overlap"), std::string::npos);
}

}  // namespace
}  // namespace vdmsim
