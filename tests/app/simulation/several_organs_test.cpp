// Scenes with several organs (`organs:`): each organ read with its own name and keys (problems
// named by the organ's place in the list), prepared and simulated with its own model, state and
// contact against every instrument, and written out organ by organ (metrics.csv columns,
// run.json's organs, --export-mesh's folders). An organ that no instrument and no other organ
// reaches moves exactly as it does alone: the scene's other organs change nothing of it. Organs
// on the core push each other (contact between organs, with friction) and pull each other
// through attachments' ties, which tear above their force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/check/scene_sanity.hpp"
#include "app/run/scene_run.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/shapes.hpp"
#include "app/simulation/tool_depth.hpp"
#include "app/scene/mesh_io.hpp"
#include "render/image.hpp"
#include "render/png_io.hpp"
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

TEST(SeveralOrgans, AttachmentsAreReadAndTheirProblemsNamed) {
  const std::string head = "name: x\norgans:\n" + organ_item("a", 0) + organ_item("b", kApart);
  const auto with = [&](const std::string& attachments, const std::string& rest = kRest) {
    return problems_of(head + "attachments: " + attachments + "\n" + rest);
  };
  EXPECT_TRUE(with("[{between: [a, b], within: 0.004}]").empty()) << text_of(with("[{between: [a, b], within: 0.004}]"));
  EXPECT_TRUE(has_problem(with("[{between: [a, c], within: 0.004}]"), "attachments[0].between[1]", "no organ is named 'c'"));
  EXPECT_TRUE(has_problem(with("[{between: [a, a], within: 0.004}]"), "attachments[0].between", "not attached to itself"));
  EXPECT_TRUE(has_problem(with("[{between: [a], within: 0.004}]"), "attachments[0].between", "expected two organ names"));
  EXPECT_TRUE(has_problem(with("[{between: [a, b]}]"), "attachments[0].within", "missing"));
  EXPECT_TRUE(has_problem(with("[{between: [a, b], within: -1}]"), "attachments[0].within", "out of range"));
  EXPECT_TRUE(has_problem(with("[{between: [a, b], within: 0.004, tear_force: 0}]"), "attachments[0].tear_force", "out of range"));
  EXPECT_TRUE(has_problem(with("[{between: [a, b], within: 0.004, glue: 1}]"), "attachments[0].glue", "unknown key", true));
  // Ties are solved with the contact between organs: the contact effect is needed.
  EXPECT_TRUE(has_problem(with("[{between: [a, b], within: 0.004}]", "simulation: {frames: 2, effects: [stress]}\n"),
                          "attachments", "add contact to simulation.effects"));
  // One organ: nothing to tie.
  EXPECT_TRUE(has_problem(problems_of("name: x\n" + organ_alone(0) + "attachments: [{between: [a, b], within: 0.004}]\n" + kRest),
                          "attachments", "give the organs as a list"));
  // `check`: livers half a metre apart tie nothing.
  const PreparedScene ps = test::prepare_scene_text("several_organs", head + "attachments: [{between: [a, b], within: 0.004}]\n" + kRest);
  EXPECT_TRUE(has_problem(scene_sanity(ps).problems, "attachments[0]", "ties nothing", true)) << text_of(scene_sanity(ps).problems);
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

// The segmentation view gives each organ its own id, named in run.json (the organs by their
// names, 1 and 2 here, the instruments after them), and both organs' ids are in its image.
TEST(SeveralOrgans, EachOrganHasItsOwnSegmentationIdNamedInRunJson) {
  const fs::path dir = test::test_output_dir("several_organs") / "segmentation";
  fs::remove_all(dir);
  PreparedScene ps = test::prepare_scene_text(
      "several_organs", two_livers() +
                            "render:\n  width: 160\n  height: 60\n  camera: {eye: [0.25, -1.2, 0.3], target: [0.25, 0, 0]}\n"
                            "  views: [segmentation]\n  hud: false\n");
  RunOptions opt;
  opt.out_dir = dir.string();
  opt.frames = 1;
  std::ostringstream out, err;
  ASSERT_EQ(run_scene(ps, opt, out, err, false), 0) << err.str();
  const std::string js = test::read_file(dir / "run.json");
  EXPECT_NE(js.find("\"segmentation_ids\": {\"left\": 1, \"right\": 2, \"instruments[0]\": 3, \"instruments[1]\": 4}"),
            std::string::npos)
      << js;
  render::Image ids;
  std::string error;
  ASSERT_TRUE(render::read_png((dir / "segmentation" / "segmentation_00000.png").string(), ids, error)) << error;
  // Each organ's pixels, and on which side of the picture (left's at x = 0, right's at 0.5 m).
  long count[3] = {0, 0, 0};
  double mean_x[3] = {0, 0, 0};
  for (int v = 0; v < ids.height; ++v)
    for (int u = 0; u < ids.width; ++u) {
      const int id = ids.rgba[static_cast<size_t>(4 * (v * ids.width + u))];
      if (id < 1 || id > 2) continue;
      ++count[id];
      mean_x[id] += u;
    }
  ASSERT_GT(count[1], 50);
  ASSERT_GT(count[2], 50);
  EXPECT_LT(mean_x[1] / count[1], ids.width / 2.0);
  EXPECT_GT(mean_x[2] / count[2], ids.width / 2.0);
}

// Organs placed into each other are an error of `check`, and a run of them stops at its first
// frame, naming both and how deep (contact between organs cannot tell which way is out).
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

// A ball of 3 cm radius (642 nodes) written to DIR/ball.obj: its path.
std::string ball_obj(const fs::path& dir) {
  std::string error;
  EXPECT_TRUE(save_obj(vdm::make_icosphere(0.03, 3), (dir / "ball.obj").string(), "ball", error)) << error;
  return (dir / "ball.obj").string();
}

// Two balls 1 mm apart, on the default model: the left one's left cap pushed 15 mm to the
// right, the right one's right cap held. The left ball presses the right one: no node of either
// goes into the other, the right one is pushed (it dents and bulges, its pressure rises), the
// two feel equal and opposite forces, and each keeps its volume.
std::string pushed_balls(const fs::path& dir) {
  const std::string ball = ball_obj(dir);
  return "name: balls\norgans:\n"
         "  - {name: pusher, mesh: " + ball + ", prescribed: [{box: {min: [-1, -1, -1], max: [-0.025, 1, 1]}, "
         "translate: [0.015, 0, 0], t: [0, 1]}]}\n"
         "  - {name: pushed, mesh: " + ball + ", translate: [0.061, 0, 0], "
         "fixed: [{box: {min: [0.086, -1, -1], max: [1, 1, 1]}}]}\n"
         "simulation: {frames: 11, dt: 0.1, effects: [contact]}\n";
}

TEST(SeveralOrgans, AnOrganPushedIntoAnotherPushesItAndDoesNotEnterIt) {
  const PreparedScene ps = test::prepare_scene_text("several_organs", pushed_balls(test::test_output_dir("several_organs")));
  SceneSimulation sim(ps);
  ASSERT_TRUE(sim.organ_contact_simulated());
  for (int f = 0; f < ps.scene.frames; ++f) {
    sim.advance(f);
    ASSERT_EQ(sim.unsound(), "") << "frame " << f;
    for (size_t i = 0; i < 2; ++i) EXPECT_LT(std::abs(sim.state(i).volume_rel_error), 1e-9) << "frame " << f;
  }
  EXPECT_EQ(sim.unconverged_contact_steps(), 0);
  const vdm::SimState &a = sim.state(0), &b = sim.state(1);
  const vdm::TriMat& triangles = ps.organs[0].model.rest.triangles;
  // No node inside the other ball (beyond the contact's tolerance).
  int inside = 0;
  double deepest = 0;
  for (int side = 0; side < 2; ++side) {
    const vdm::SimState &own = side ? b : a, &other = side ? a : b;
    for (Eigen::Index i = 0; i < own.x.rows(); ++i) {
      const double d = depth_inside(other.x, triangles, own.x.row(i).transpose());
      deepest = std::max(deepest, d);
      if (d > 1e-4) ++inside;
    }
  }
  EXPECT_LE(inside, int(0.005 * (a.x.rows() + b.x.rows()))) << "deepest " << deepest;
  // The pushed ball is pushed: its near side moved toward +x by most of the 14 mm overlap the
  // push would have made, and it holds the pusher's force.
  const double pushed = b.u.col(0).maxCoeff();
  EXPECT_GT(pushed, 0.004);
  const vdm::Vec3 on_pushed = sim.organ_contact_force(1), on_pusher = sim.organ_contact_force(0);
  EXPECT_GT(on_pushed.x(), 0.0);
  EXPECT_NEAR((on_pushed + on_pusher).norm(), 0.0, 1e-9 * on_pushed.norm());
  EXPECT_GT(b.pressure, 0.0);
  std::cout << "pushed " << pushed * 1e3 << " mm, force " << on_pushed.transpose() << " N, inside " << inside
            << ", deepest " << deepest * 1e3 << " mm, pressures " << a.pressure << " " << b.pressure << "\n";
}

// Two balls 1 mm apart, the left one's nodes tied to the right one's surface where they face
// (within 2 mm); the left one's left cap pulled 8 mm away, the right one's right cap held.
std::string tied_balls(const fs::path& dir, const std::string& tear) {
  const std::string ball = ball_obj(dir);
  return "name: tied\norgans:\n"
         "  - {name: pulled, mesh: " + ball + ", prescribed: [{box: {min: [-1, -1, -1], max: [-0.025, 1, 1]}, "
         "translate: [-0.008, 0, 0], t: [0, 1]}]}\n"
         "  - {name: held, mesh: " + ball + ", translate: [0.061, 0, 0], "
         "fixed: [{box: {min: [0.086, -1, -1], max: [1, 1, 1]}}]}\n"
         "attachments: [{between: [pulled, held], within: 0.002" + tear + "}]\n"
         "simulation: {frames: 9, dt: 0.125, effects: [contact]}\n";
}

// The tied ball drags its neighbour: the held ball's near side follows the pulled one (its
// ties hold it), the two feel equal and opposite forces, and each keeps its volume.
TEST(SeveralOrgans, AnOrganTiedToAnotherDragsIt) {
  const PreparedScene ps = test::prepare_scene_text("several_organs", tied_balls(test::test_output_dir("several_organs"), ""));
  SceneSimulation sim(ps);
  ASSERT_TRUE(sim.organ_contact_simulated());
  EXPECT_GT(sim.organ_ties(), 3);
  for (int f = 0; f < ps.scene.frames; ++f) {
    sim.advance(f);
    ASSERT_EQ(sim.unsound(), "") << "frame " << f;
    for (size_t i = 0; i < 2; ++i) EXPECT_LT(std::abs(sim.state(i).volume_rel_error), 1e-9) << "frame " << f;
  }
  EXPECT_EQ(sim.unconverged_contact_steps(), 0);
  EXPECT_EQ(sim.organ_ties_torn(), 0);
  const vdm::SimState& held = sim.state(1);
  // The held ball's nearest node to the pulled one: dragged toward -x by a good part of the pull.
  Eigen::Index near = 0;
  ps.organs[1].model.rest.positions.col(0).minCoeff(&near);
  const double dragged = -held.u(near, 0);
  EXPECT_GT(dragged, 0.002);
  EXPECT_LT(dragged, 0.008);
  const vdm::Vec3 on_held = sim.organ_contact_force(1), on_pulled = sim.organ_contact_force(0);
  EXPECT_LT(on_held.x(), 0.0);
  EXPECT_NEAR((on_held + on_pulled).norm(), 0.0, 1e-9 * on_held.norm());
  std::cout << "dragged " << dragged * 1e3 << " mm by " << sim.organ_ties() << " ties, force " << on_held.transpose()
            << " N\n";
}

// The forces the others put on an organ, per node (organ_contact_forces), sum to its total.
// And an organ simulated alone with its neighbour following the surface recorded in a run of
// the whole scene (record_organ_surface, follow_recorded_surface: what the organs' cost
// benchmark does) deforms as it deformed in the whole scene: a static organ's answer depends
// only on where its neighbour is, which its ties and contact meet.
TEST(SeveralOrgans, AnOrganWhoseNeighbourFollowsItsRecordedSurfaceDeformsAsInTheScene) {
  const fs::path dir = test::test_output_dir("several_organs");
  const PreparedScene both = test::prepare_scene_text("several_organs", tied_balls(dir, ""));
  SceneSimulation sim(both);
  SceneSimulation::SubstepSurfaces pulled;
  sim.record_organ_surface(0, &pulled);
  for (int f = 0; f < both.scene.frames; ++f) {
    sim.advance(f);
    ASSERT_EQ(sim.unsound(), "") << "frame " << f;
    ASSERT_EQ(pulled.size(), static_cast<size_t>(f + 1));
    ASSERT_FALSE(pulled.back().empty()) << "frame " << f;
    EXPECT_EQ(pulled.back().back(), sim.state(0).x) << "frame " << f;  // the frame's last sub-step's
    const vdm::Vec3 sum = sim.organ_contact_forces(1).colwise().sum().transpose();
    EXPECT_LT((sum - sim.organ_contact_force(1)).norm(), 1e-12 + 1e-9 * sum.norm()) << "frame " << f;
  }
  SceneSimulation alone(both);
  alone.follow_recorded_surface(0, &pulled);
  for (int f = 0; f < both.scene.frames; ++f) {
    alone.advance(f);
    ASSERT_EQ(alone.unsound(), "") << "frame " << f;
    EXPECT_EQ(alone.state(0).x, pulled[static_cast<size_t>(f)].back()) << "frame " << f;  // followed, not simulated
  }
  EXPECT_EQ(alone.unconverged_contact_steps(), 0);
  const vdm::NodeMat& u_scene = sim.state(1).u;
  const vdm::NodeMat& u_alone = alone.state(1).u;
  const double moved = u_scene.cwiseAbs().maxCoeff(), apart = (u_alone - u_scene).cwiseAbs().maxCoeff();
  EXPECT_GT(moved, 0.002);
  // Within a few of the core's tolerances (1e-4 of the 5 cm ball's size): the two runs stop
  // their iterations at different points.
  EXPECT_LT(apart, 0.01 * moved);
  EXPECT_LT(std::abs(alone.state(1).volume_rel_error), 1e-9);
  std::cout << "the held ball moved " << moved * 1e3 << " mm in the scene; alone, the pulled one following, "
            << apart * 1e6 << " um apart\n";
  // With the pulled ball following its rest surface instead, the held ball does not move.
  SceneSimulation::SubstepSurfaces at_rest(pulled.size(), {both.organs[0].model.rest.positions});
  SceneSimulation still(both);
  still.follow_recorded_surface(0, &at_rest);
  for (int f = 0; f < both.scene.frames; ++f) still.advance(f);
  EXPECT_LT(still.state(1).u.cwiseAbs().maxCoeff(), 1e-6);
}

// With a small tear force the ties let go as the pull grows: every one tears, and the held ball
// then springs back to its rest shape.
TEST(SeveralOrgans, TiesTearAboveTheirTearForceAndLetGo) {
  const PreparedScene ps =
      test::prepare_scene_text("several_organs", tied_balls(test::test_output_dir("several_organs"), ", tear_force: 0.002"));
  SceneSimulation sim(ps);
  int torn_before_end = -1;
  for (int f = 0; f < ps.scene.frames; ++f) {
    sim.advance(f);
    ASSERT_EQ(sim.unsound(), "") << "frame " << f;
    if (f == 1) torn_before_end = sim.organ_ties_torn();
  }
  EXPECT_LT(torn_before_end, sim.organ_ties());
  EXPECT_EQ(sim.organ_ties_torn(), sim.organ_ties());
  EXPECT_LT(sim.state(1).u.cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(sim.organ_contact_force(1).norm(), 0.0);
}

// A run of organs in contact (with friction, which carries the points pressed from one step to
// the next) saved halfway and loaded into a new simulation ends bit for bit as the whole run.
TEST(SeveralOrgans, ARunOfOrgansInContactResumedFromASnapshotEqualsTheWholeRun) {
  const PreparedScene ps = test::prepare_scene_text("several_organs", pushed_balls(test::test_output_dir("several_organs")));
  SceneSimulation whole(ps), first(ps), resumed(ps);
  std::string snapshot, error;
  for (int f = 0; f < ps.scene.frames; ++f) {
    whole.advance(f);
    if (f < 6) first.advance(f);
  }
  ASSERT_TRUE(first.save(snapshot));
  ASSERT_TRUE(resumed.load(snapshot, error)) << error;
  for (int f = 6; f < ps.scene.frames; ++f) resumed.advance(f);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(whole.state(i).u == resumed.state(i).u) << "organ " << i;
    EXPECT_EQ(whole.organ_contact_force(i), resumed.organ_contact_force(i)) << "organ " << i;
  }
  // A snapshot of other organs is refused.
  const PreparedScene tied = test::prepare_scene_text("several_organs", tied_balls(test::test_output_dir("several_organs"), ""));
  SceneSimulation other(tied);
  EXPECT_FALSE(other.load(snapshot, error));
}

}  // namespace
}  // namespace vdmsim
