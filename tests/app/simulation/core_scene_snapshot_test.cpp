// Scene snapshots of the default organ model, vdm_core (the elastic core): a SceneSimulation
// loaded from the snapshot of another continues bit for bit like it, with constraint contact
// and friction (a probe that presses, then slides), with kinematic contact, and with a grasper
// holding tissue across the snapshot; a cut snapshot, or one of another lattice, is refused.
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

PreparedScene prepare(const std::string& text) { return test::prepare_scene_text("core_scene_snapshot", text); }

// The liver on the default model (no organ.model), its base fixed; `rest` is the scene's
// simulation and instruments.
std::string liver_scene(const std::string& organ_extra, const std::string& rest) {
  return std::string("name: core_snap\norgan:\n  mesh: ") + VDMSIM_SOURCE_DIR + "/assets/meshes/liver_L4.obj\n" +
         "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n" + organ_extra + rest;
}

const std::string kPressAndSlide =
    "simulation: {frames: 14, dt: 0.05, effects: [contact, stress]}\n"
    "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.062], "
    "axis: [0, 0, -1]}, {t: 0.3, tip: [0.035, 0, 0.05]}, {t: 0.7, tip: [0.05, 0, 0.05]}]}\n";

// Simulates frames 0 to `saved` - 1 on `a`, loads a fresh simulation from its snapshot and
// steps both to `frames`: the same bits every frame, and the same tallies at the end.
void expect_continues_bit_for_bit(const PreparedScene& ps, SceneSimulation& a, int saved, int frames) {
  std::string bytes, error;
  ASSERT_TRUE(a.save(bytes)) << "vdm_core's state is saved";
  SceneSimulation b(ps);
  ASSERT_TRUE(b.load(bytes, error)) << error;
  for (int f = saved; f < frames; ++f) {
    a.advance(f);
    b.advance(f);
    ASSERT_FALSE(a.state().failed) << a.state().failure;
    ASSERT_EQ(b.state().u, a.state().u) << "frame " << f;
    ASSERT_EQ(b.state().pressure, a.state().pressure) << "frame " << f;
    EXPECT_EQ(b.state().stress, a.state().stress) << "frame " << f;
    EXPECT_EQ(b.frame_iterations(), a.frame_iterations()) << "frame " << f;
    EXPECT_EQ(b.contact_report().nodes, a.contact_report().nodes) << "frame " << f;
    EXPECT_EQ(b.contact_report().force, a.contact_report().force) << "frame " << f;
    EXPECT_EQ(b.total_force(), a.total_force()) << "frame " << f;
  }
  EXPECT_EQ(b.peak_forces(), a.peak_forces());
  EXPECT_EQ(b.contact_iterations(), a.contact_iterations());
  EXPECT_EQ(b.unconverged_contact_steps(), a.unconverged_contact_steps());
  EXPECT_EQ(b.state().warnings, a.state().warnings);
}

TEST(CoreSceneSnapshot, ConstraintContactWithFrictionContinuesBitForBit) {
  // The default contact (constraint, friction 0.2) solved inside the core's iteration: its
  // contact points' forces and the core's held factors and rotations carry over.
  const PreparedScene ps = prepare(liver_scene("", kPressAndSlide));
  ASSERT_EQ(ps.scene.organ().model, vdm::ModelKind::vdm_core) << "the default model";
  SceneSimulation a(ps);
  for (int f = 0; f < 7; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed) << a.state().failure;
  ASSERT_GT(a.contact_report().nodes, 0) << "the probe touches by now";
  expect_continues_bit_for_bit(ps, a, 7, 11);  // (sliding from frame 7 on)
  EXPECT_GT(a.contact_report().force.norm(), 0.0) << "the probe presses";
}

TEST(CoreSceneSnapshot, KinematicContactContinuesBitForBit) {
  // Kinematic contact holds the nodes under the probe as prescribed entries (held through the
  // core's factor by multipliers); what it reads of the last step (velocities, reactions) is
  // the SimState's.
  std::string scene = kPressAndSlide;
  scene.replace(scene.find("effects: [contact, stress]"), 26, "effects: [contact, stress], contact: {method: kinematic}");
  const PreparedScene ps = prepare(liver_scene("", scene));
  ASSERT_EQ(ps.scene.contact.method, vdm::ContactSettings::Method::kinematic);
  SceneSimulation a(ps);
  for (int f = 0; f < 7; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed) << a.state().failure;
  ASSERT_GT(a.contact_report().nodes, 0) << "the probe holds nodes by now";
  expect_continues_bit_for_bit(ps, a, 7, 11);
}

TEST(CoreSceneSnapshot, AGraspHeldAcrossTheSnapshotContinuesBitForBit) {
  // The grasper closes on the right lobe at t = 0.1 s and lifts it 2 cm by t = 0.45 s; the
  // snapshot is taken while it holds (its nodes prescribed: held by multipliers through the
  // core's factor), with the jaws' contact on.
  const PreparedScene ps = prepare(liver_scene(
      "", "simulation: {frames: 10, dt: 0.05, effects: [contact, grasp, stress]}\n"
          "instruments:\n  - {type: grasper, radius: 0.005, jaw_length: 0.015, grasp_width: 0.006, script: ["
          "{t: 0, tip: [0.035, 0, 0.0603], axis: [0, 0, -1], jaw: open}, {t: 0.1, jaw: closed},"
          " {t: 0.45, tip: [0.035, 0, 0.0803]}]}\n"));
  SceneSimulation a(ps);
  for (int f = 0; f < 5; ++f) a.advance(f);
  ASSERT_FALSE(a.state().failed) << a.state().failure;
  ASSERT_LT(a.total_force().z(), -0.1) << "the grasper holds and lifts by now";
  expect_continues_bit_for_bit(ps, a, 5, 10);
  // The grasp held on: the tissue at the jaws was lifted with them (2 cm by the last frame).
  EXPECT_GT(a.state().u.col(2).maxCoeff(), 0.01);
}

TEST(CoreSceneSnapshot, ACutSnapshotOrOneOfAnotherLatticeIsRefused) {
  const PreparedScene ps = prepare(liver_scene("", kPressAndSlide));
  SceneSimulation a(ps);
  for (int f = 0; f < 5; ++f) a.advance(f);
  std::string bytes, error;
  ASSERT_TRUE(a.save(bytes));
  // Cut in the core's part (first), in the engine's and at the end.
  for (size_t cut : {size_t(100), bytes.size() / 2, bytes.size() - 3}) {
    SceneSimulation c(ps);
    EXPECT_FALSE(c.load(std::string_view(bytes).substr(0, cut), error)) << "cut at " << cut;
    EXPECT_EQ(error.rfind("state snapshot", 0), 0u) << error;
  }
  // The same organ on a coarser lattice.
  const PreparedScene coarser = prepare(liver_scene("  cell_size: 0.02\n", kPressAndSlide));
  SceneSimulation d(coarser);
  EXPECT_FALSE(d.load(bytes, error));
  EXPECT_NE(error.find("of another lattice"), std::string::npos) << error;
}

}  // namespace
}  // namespace vdmsim
