// The automatic colour range of a contact-pressure view follows the instruments' contact
// patches, not the many small reactions of the fixed nodes the organ rests on.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/run/scene_run.hpp"
#include "app/simulation/scene_simulation.hpp"

namespace fs = std::filesystem;

TEST(ColourRange, ContactPressureRangeSpansTheContactPatch) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "colour_range";
  fs::create_directories(out);
  const fs::path scene = out / "press.yaml";
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 3, dt: 0.1, effects: [contact]}\n"
                          "instruments:\n  - type: probe\n    radius: 0.008\n"
                          "    script: [{t: 0, tip: [0.035, 0, 0.0603], axis: [0, 0, -1]}, {t: 0.3, tip: [0.035, 0, 0.0523]}]\n"
                          "render: {width: 160, height: 120, views: [stress], hud: false,\n"
                          "         stress: {quantity: contact_pressure}}\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::prepare_scene(scene.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  // The largest contact pressure on a node the scene does not hold, and on held nodes.
  double patch = 0.0, support = 0.0;
  vdmsim::SceneSimulation sim(ps);
  for (int f = 0; f < 3; ++f) {
    sim.advance(f);
    const vdm::SimState& s = sim.state();
    for (int i = 0; i < ps.organ().model.n; ++i) {
      double& most = ps.organ().model.held.row(i).minCoeff() ? support : patch;
      most = std::max(most, s.reaction_pressure[i]);
    }
  }
  ASSERT_GT(patch, 0.0);
  ASSERT_GT(support, 0.0);  // the organ rests on its fixed underside: reactions there too
  vdmsim::RunOptions opt;
  opt.out_dir = (out / "run").string();
  std::ostringstream o, e;
  ASSERT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 0) << e.str();
  std::ifstream f(out / "run" / "run.json");
  const std::string json((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const size_t at = json.find("\"stress_range\": [");
  ASSERT_NE(at, std::string::npos) << json;
  double lo = -1, hi = -1;
  char comma = 0;
  std::istringstream(json.substr(at + 17)) >> lo >> comma >> hi;
  EXPECT_EQ(lo, 0.0);
  // Fewer than 200 nodes in contact: the 99.5 % quantile of the patch is its largest value.
  EXPECT_NEAR(hi, patch, 1e-6 * patch) << json;
}
