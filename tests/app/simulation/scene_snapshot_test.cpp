// Scene snapshots (resume from a state snapshot): a SceneSimulation loaded from the snapshot
// of another after some frames (contact, a closed grasp holding nodes, a probe) continues bit
// for bit like it; a reference model's simulation is not saved (its resume re-simulates).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/simulation/scene_simulation.hpp"
#include "support/scene_text.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

fs::path dir() { return test::test_output_dir("scene_snapshot"); }

PreparedScene prepare(const std::string& text) { return test::prepare_scene_text("scene_snapshot", text); }

TEST(SceneSnapshot, ALoadedSimulationWithContactAndAGraspContinuesBitForBit) {
  const PreparedScene ps = prepare(
      std::string("name: snap\norgan:\n  mesh: ") + VDMSIM_SOURCE_DIR +
      "/assets/meshes/liver_L4.obj\n  model: vdm\n"
      "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
      "simulation: {frames: 16, dt: 0.05, effects: [contact, grasp, stress]}\n"
      "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.065], "
      "axis: [0, 0, -1]}, {t: 0.8, tip: [0.035, 0, 0.045]}]}\n"
      "  - {type: grasper, script: [{t: 0, tip: [-0.08, 0, 0.05], axis: [0, 0, -1], jaw: open},"
      " {t: 0.1, tip: [-0.08, 0, 0.037]}, {t: 0.15, jaw: closed}, {t: 0.8, tip: [-0.08, 0, 0.052]}]}\n");
  SceneSimulation a(ps);
  for (int f = 0; f < 6; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed);
  ASSERT_GT(a.contact_report().nodes, 0) << "the probe touches by now";
  std::string bytes;
  ASSERT_TRUE(a.save(bytes));
  SceneSimulation b(ps);
  std::string error;
  ASSERT_TRUE(b.load(bytes, error)) << error;
  for (int f = 6; f < 16; ++f) {
    a.advance(f);
    b.advance(f);
    ASSERT_EQ(b.state().u, a.state().u) << "frame " << f;
    ASSERT_EQ(b.state().pressure, a.state().pressure) << "frame " << f;
    EXPECT_EQ(b.frame_iterations(), a.frame_iterations()) << "frame " << f;
    EXPECT_EQ(b.contact_report().nodes, a.contact_report().nodes) << "frame " << f;
    EXPECT_EQ(b.contact_report().force, a.contact_report().force) << "frame " << f;
  }
  // The grasp held on: nodes at the jaws were lifted with them (about 14 mm by the last frame).
  double lifted = 0;
  for (int i = 0; i < ps.organ().model.n; ++i)
    if ((ps.organ().model.rest.positions.row(i) - vdm::Vec3(-0.08, 0, 0.041).transpose()).norm() < 0.008)
      lifted = std::max(lifted, b.state().u(i, 2));
  EXPECT_GT(lifted, 0.005);
  // A cut snapshot is refused.
  SceneSimulation c(ps);
  EXPECT_FALSE(c.load(std::string_view(bytes).substr(0, bytes.size() - 5), error));
  EXPECT_NE(error.find("state snapshot"), std::string::npos) << error;
}

TEST(SceneSnapshot, PenaltyContactContinuesBitForBit) {
  // Penalty contact keeps nothing between frames; its springs reach the engine in StepInput
  // and the matrices of the last step keep them (the snapshot carries them).
  const PreparedScene ps = prepare(
      std::string("name: snap\norgan:\n  mesh: ") + VDMSIM_SOURCE_DIR +
      "/assets/meshes/liver_L4.obj\n  model: vdm\n"
      "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
      "simulation: {frames: 12, dt: 0.05, effects: [contact, stress], contact: {method: penalty}}\n"
      "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.065], "
      "axis: [0, 0, -1]}, {t: 0.6, tip: [0.035, 0, 0.045]}]}\n");
  SceneSimulation a(ps);
  for (int f = 0; f < 5; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed) << a.state().failure;
  std::string bytes, error;
  ASSERT_TRUE(a.save(bytes));
  SceneSimulation b(ps);
  ASSERT_TRUE(b.load(bytes, error)) << error;
  for (int f = 5; f < 12; ++f) {
    a.advance(f);
    b.advance(f);
    ASSERT_EQ(b.state().u, a.state().u) << "frame " << f;
    EXPECT_EQ(b.frame_iterations(), a.frame_iterations()) << "frame " << f;
    EXPECT_EQ(b.contact_report().force, a.contact_report().force) << "frame " << f;
  }
  EXPECT_GT(a.contact_report().force.norm(), 0.0) << "the probe presses";
}

TEST(SceneSnapshot, ConstraintContactWithFrictionContinuesBitForBit) {
  // Constraint contact carries its contact forces (the next step's warm start) and the
  // compliance's fitted scale over: the snapshot must too. The probe presses, then slides.
  const PreparedScene ps = prepare(
      std::string("name: snap\norgan:\n  mesh: ") + VDMSIM_SOURCE_DIR +
      "/assets/meshes/liver_L4.obj\n  model: vdm\n"
      "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
      "simulation: {frames: 14, dt: 0.05, effects: [contact, stress], contact: {method: constraint, friction: 0.3}}\n"
      "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.062], "
      "axis: [0, 0, -1]}, {t: 0.3, tip: [0.035, 0, 0.05]}, {t: 0.7, tip: [0.05, 0, 0.05]}]}\n");
  SceneSimulation a(ps);
  for (int f = 0; f < 7; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed) << a.state().failure;
  ASSERT_GT(a.contact_report().nodes, 0) << "the probe touches by now";
  std::string bytes, error;
  ASSERT_TRUE(a.save(bytes));
  SceneSimulation b(ps);
  ASSERT_TRUE(b.load(bytes, error)) << error;
  for (int f = 7; f < 14; ++f) {
    a.advance(f);
    b.advance(f);
    ASSERT_EQ(b.state().u, a.state().u) << "frame " << f;
    EXPECT_EQ(b.frame_iterations(), a.frame_iterations()) << "frame " << f;
    EXPECT_EQ(b.contact_report().force, a.contact_report().force) << "frame " << f;
  }
  EXPECT_GT(a.contact_report().force.norm(), 0.0) << "the probe presses";
  SceneSimulation c(ps);
  EXPECT_FALSE(c.load(std::string_view(bytes).substr(0, bytes.size() - 3), error));
  EXPECT_NE(error.find("state snapshot"), std::string::npos) << error;
}

TEST(SceneSnapshot, AReferenceModelIsNotSaved) {
  const fs::path box = dir() / "box.obj";
  std::ofstream(box) << "v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const PreparedScene ps = prepare("name: ms\norgan:\n  mesh: " + box.string() +
                                   "\n  model: mass_spring\n  material: {young_modulus: 3000, poisson_ratio: 0.45}\n"
                                   "simulation: {frames: 2, dt: 0.1, effects: []}\n");
  SceneSimulation a(ps);
  std::string bytes, error;
  EXPECT_FALSE(a.save(bytes));
  EXPECT_FALSE(a.load(bytes, error));
}

}  // namespace
}  // namespace vdmsim
