// Frame f of a run is the scene at t = f dt: frame 0 is the scene at t = 0, before the script
// moves anything (the organ at rest, the instruments at their first keyframe's pose), and every
// output labels it so (metrics.csv's time_s, the pictures' HUD, the mesh export's times).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/simulation/scene_simulation.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

fs::path frame_time_dir() { return test::scratch_dir("frame_time"); }

// The 2,562-node liver, its base held, and a 4 mm probe whose tip starts at `start` and goes
// 5 cm down over 1 s. `effects` and `frames` as given (dt 0.05 s).
std::string probe_scene(const std::string& start, const std::string& effects, int frames) {
  return "name: frame_time\norgan:\n  mesh: " + (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string() +
         "\n  material: {bulk_modulus: 20000, connectivity_modulus: 2000, density: 1060}\n"
         "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
         "simulation: {frames: " + std::to_string(frames) + ", dt: 0.05, effects: [" + effects + "]}\n"
         "instruments:\n  - type: probe\n    radius: 0.004\n    script:\n"
         "      - {t: 0.0, tip: " + start + ", axis: [0, 0, -1]}\n"
         "      - {t: 1.0, tip: [0.035, 0.0, 0.04]}\n";
}

PreparedScene prepare(const std::string& name, const std::string& text) {
  const fs::path p = frame_time_dir() / name;
  std::ofstream(p) << text;
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  return ps;
}

double largest_displacement(const SceneSimulation& sim) { return sim.state().u.rowwise().norm().maxCoeff(); }

TEST(FrameTime, FrameZeroIsTheSceneAtTimeZeroAndFrameFAtFTimesDt) {
  // The probe starts 3 cm above the organ and reaches it after about 0.6 s.
  const PreparedScene ps = prepare("above.yaml", probe_scene("[0.035, 0.0, 0.09]", "contact", 16));
  SceneSimulation sim(ps);
  const InstrumentDef& probe = ps.scene.instruments.at(0);
  sim.advance(0);
  EXPECT_EQ(sim.time(), 0.0);
  EXPECT_EQ(largest_displacement(sim), 0.0) << "nothing touches the organ at t = 0: it is at rest";
  EXPECT_EQ(sim.state().pressure, 0.0);
  EXPECT_EQ(sim.contact_report().nodes, 0);
  EXPECT_EQ(sim.poses(sim.time()).at(0).tip, probe.script.front().tip) << "the probe at its t = 0 pose";
  double deepest = 0;
  for (int f = 1; f < ps.scene.frames; ++f) {
    sim.advance(f);
    EXPECT_DOUBLE_EQ(sim.time(), f * ps.scene.dt) << "frame " << f;
    EXPECT_DOUBLE_EQ(SceneSimulation::frame_time(f, ps.scene.dt), sim.time());
    deepest = std::max(deepest, largest_displacement(sim));
  }
  // The last frame is at 0.75 s: the tip has come 3.75 cm down, into the organ.
  EXPECT_DOUBLE_EQ(sim.poses(sim.time()).at(0).tip.z(), 0.09 - 0.05 * 0.75);
  EXPECT_GT(deepest, 1e-3) << "the probe pressed the organ in the later frames";
}

TEST(FrameTime, AProbeStartingInsideIsPushedOutAtFrameZeroWithoutMoving) {
  // Quasi-static: frame 0 is the equilibrium at t = 0, the contact of a probe that starts 5 mm
  // inside the rest surface resolved, the probe where its first keyframe puts it.
  const PreparedScene ps = prepare("inside.yaml", probe_scene("[0.035, 0.0, 0.055]", "contact", 2));
  SceneSimulation sim(ps);
  sim.advance(0);
  EXPECT_EQ(sim.time(), 0.0);
  EXPECT_TRUE(sim.frame_stepped());
  EXPECT_FALSE(sim.state().failed) << sim.state().failure;
  EXPECT_GT(sim.contact_report().nodes, 0);
  EXPECT_GT(largest_displacement(sim), 2e-3) << "the organ pushed out of the probe";
  EXPECT_GT(sim.instrument_forces().at(0).z(), 0.0) << "the organ pushes the probe up";
  EXPECT_EQ(sim.poses(0.0).at(0).tip, ps.scene.instruments.at(0).script.front().tip);
}

TEST(FrameTime, WithInertiaFrameZeroIsTheInitialConditionAtRest) {
  // Gravity and inertia: the organ starts at rest and only then falls; frame 0 takes no step.
  const PreparedScene ps = prepare("inertia.yaml", probe_scene("[0.035, 0.0, 0.09]", "contact, gravity, inertia", 3));
  SceneSimulation sim(ps);
  sim.advance(0);
  EXPECT_EQ(sim.time(), 0.0);
  EXPECT_FALSE(sim.frame_stepped());
  EXPECT_EQ(largest_displacement(sim), 0.0);
  EXPECT_EQ(sim.state().velocity.cwiseAbs().maxCoeff(), 0.0);
  sim.advance(1);
  EXPECT_TRUE(sim.frame_stepped());
  EXPECT_EQ(sim.time(), ps.scene.dt);
  EXPECT_GT(largest_displacement(sim), 0.0) << "gravity moves the organ from the first step on";
}

// metrics.csv: row f has time_s f dt, and row 0 the organ at rest.
TEST(FrameTime, MetricsTimeOfFrameFIsFTimesDt) {
  const fs::path scene = frame_time_dir() / "run.yaml", out = frame_time_dir() / "run_out";
  std::ofstream(scene) << probe_scene("[0.035, 0.0, 0.09]", "contact", 16);
  fs::remove_all(out);
  const auto r = test::run_cli(VDMSIM_BINARY, "run " + scene.string() + " --no-render --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(out / "metrics.csv");
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line.rfind("frame,time_s,", 0), 0u) << line;
  int rows = 0;
  double deepest = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
    ASSERT_GE(cells.size(), 15u) << line;
    EXPECT_EQ(std::stoi(cells[0]), rows);
    EXPECT_NEAR(std::stod(cells[1]), rows * 0.05, 1e-12) << line;
    const double moved = std::stod(cells[14]);  // max_displacement_m
    if (rows == 0) {
      EXPECT_EQ(moved, 0.0) << "frame 0 is the organ at rest: " << line;
    }
    deepest = std::max(deepest, moved);
    ++rows;
  }
  EXPECT_EQ(rows, 16) << "frames: 16 writes frames 0 to 15";
  EXPECT_GT(deepest, 1e-3);
}

}  // namespace
}  // namespace vdmsim
