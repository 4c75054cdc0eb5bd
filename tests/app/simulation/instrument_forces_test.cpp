// The force of the organ on each instrument (SceneSimulation::instrument_forces): a grasper's
// includes the reactions of the nodes it holds, so lifting the liver by its jaws reports a
// downward pull that grows with the lift; a probe's is its contact force.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "app/simulation/scene_simulation.hpp"

namespace vdmsim {
namespace {

PreparedScene prepare_example(const std::string& name) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  const auto path = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/scenes" / name;
  EXPECT_TRUE(prepare_scene(path.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  return ps;
}

TEST(InstrumentForces, AGraspAndLiftPullsTheJawsDownHarderAsItLifts) {
  // grasp_lift.yaml: the jaws close at 0.6 s and lift the lobe 20 mm by 1.6 s (frames 18 to 48).
  PreparedScene ps = prepare_example("grasp_lift.yaml");
  ps.scene.has_render = false;
  SceneSimulation sim(ps);
  ASSERT_TRUE(sim.forces_simulated());
  std::vector<double> fz;  // per frame of the lift
  for (int f = 0; f < 48; ++f) {
    sim.advance(f);
    if (f >= 20) fz.push_back(sim.instrument_forces()[0].z());
  }
  EXPECT_LT(fz.front(), 0.0) << "the held tissue pulls the jaws down";
  for (size_t k = 5; k < fz.size(); k += 5) EXPECT_LT(fz[k], fz[k - 5]) << "frame " << 20 + k;
  EXPECT_LT(fz.back(), 4 * fz.front());
  EXPECT_NEAR(sim.total_force().z(), fz.back(), 1e-12);
  EXPECT_DOUBLE_EQ(sim.peak_forces()[0], std::max(sim.peak_forces()[0], sim.instrument_forces()[0].norm()));
  EXPECT_GE(sim.peak_forces()[0], -fz.back());
}

TEST(InstrumentForces, AProbesForceIsItsContactForce) {
  PreparedScene ps = prepare_example("probe_poke.yaml");
  ps.scene.has_render = false;
  SceneSimulation sim(ps);
  for (int f = 0; f < 40; ++f) sim.advance(f);
  ASSERT_GT(sim.contact_report().nodes, 0);
  EXPECT_GT(sim.instrument_forces()[0].z(), 0.1) << "the organ pushes the probe up";
  EXPECT_LT((sim.instrument_forces()[0] - sim.contact_report().force).norm(), 1e-9 * sim.contact_report().force.norm());
  EXPECT_EQ(sim.unconverged_contact_steps(), 0);
  EXPECT_GT(sim.contact_iterations(), 0);
}

}  // namespace
}  // namespace vdmsim
