// The run loop under solver trouble (issue 7): fallbacks are counted in metrics.csv; a step
// the engine cannot do stops the run cleanly, keeping every frame so far, and run.json says why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/cli/commands.hpp"
#include "app/run/scene_run.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// One folder per test (tests run in parallel), under the build tree.
fs::path dir() {
  const fs::path d = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "run_robust" /
                     ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(d);
  return d;
}

std::string scene(const std::string& solver) {
  const fs::path p = dir() / "scene.yaml";
  std::ofstream(p) << "name: robust\n"
                      "organ:\n"
                      "  mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string() << "\n"
                      "  model: vdm\n"  // the surface solver's fallbacks
                      "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\n"
                      "  prescribed: [{sphere: {center: [0.035, -0.01, 0.06], radius: 0.015}, translate: [0, 0, -0.01], t: [0, 0.12]}]\n"
                      "simulation:\n"
                      "  frames: 3\n"
                      "  dt: 0.04\n"
                      "  solver: " << solver << "\n";
  return p.string();
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(RunRobust, FallbacksAreCountedInTheLastMetricsColumn) {
  const fs::path out = dir() / "fallback_out";
  fs::remove_all(out);
  std::ostringstream o, e;
  ASSERT_EQ(cmd_run(scene("{method: structured, max_iterations: 1}"), out.string(), -1, false, false, false, 30, o, e, false), 0)
      << e.str();
  std::istringstream csv(read(out / "metrics.csv"));
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.substr(header.rfind(',') + 1), "fallbacks");
  int rows = 0;
  while (std::getline(csv, row)) {
    ++rows;
    EXPECT_EQ(row.substr(row.rfind(',') + 1), "1") << row;  // one solve per frame, redone directly
  }
  EXPECT_EQ(rows, 3);
  EXPECT_NE(read(out / "run.json").find("\"status\": \"completed\""), std::string::npos);
  EXPECT_NE(read(out / "run.json").find("redone by the direct solver"), std::string::npos);
}

TEST(RunRobust, AStepTheEngineCannotDoStopsTheRunWithTheReason) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  ASSERT_TRUE(prepare_scene(scene("{method: structured}"), ps, problems));
  ps.organ().model.bulk(0, 0) = std::nan("");  // every solver now meets NaN
  const fs::path out = dir() / "fail_out";
  fs::remove_all(out);
  RunOptions opt;
  opt.out_dir = out.string();
  opt.render = false;
  std::ostringstream o, e;
  EXPECT_EQ(run_scene(ps, opt, o, e, false), 1);
  const std::string json = read(out / "run.json");
  EXPECT_NE(json.find("\"status\": \"failed\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"reason\": \"frame 0: no solver could solve the step"), std::string::npos) << json;
  EXPECT_NE(json.find("\"frames\": 0"), std::string::npos) << json;
  // metrics.csv is complete: its header, no half row.
  const std::string csv = read(out / "metrics.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1) << csv;
}

// A frame the renderer cannot draw (OpenGL refusing to map the organ's buffer, made to
// happen at frame 3): the run stops there with the reason, and the frames before it stay,
// every image whole and one metrics row each.
TEST(RunRobust, AFrameTheRendererCannotDrawStopsTheRunAndKeepsTheFramesBefore) {
  const fs::path p = dir() / "render.yaml";
  std::ofstream(p) << std::ifstream(scene("{method: structured}")).rdbuf()
                   << "  effects: [stress]\nrender: {width: 96, height: 64, views: [shaded, stress], hud: false}\n";
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  ASSERT_TRUE(prepare_scene((dir() / "render.yaml").string(), ps, problems))
      << (problems.empty() ? std::string() : problems.front().text());
  ps.scene.frames = 8;
  const fs::path out = dir() / "render_out";
  fs::remove_all(out);
  RunOptions opt;
  opt.out_dir = out.string();
  opt.fail_render_at_frame = 3;
  std::ostringstream o, e;
  EXPECT_EQ(run_scene(ps, opt, o, e, false), 1);
  const std::string json = read(out / "run.json");
  EXPECT_NE(json.find("\"status\": \"failed\""), std::string::npos) << json;
  EXPECT_NE(json.find("rendering frame 3 failed: OpenGL could not map the organ's vertex buffer"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"frames\": 3"), std::string::npos) << json;
  const std::string csv = read(out / "metrics.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;  // the header and frames 0-2
  for (int f = 0; f < 8; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "%05d.png", f);
    for (const char* view : {"frames/frame_", "stress/stress_"}) {
      const fs::path image = out / (std::string(view) + name);
      EXPECT_EQ(fs::exists(image), f < 3) << image;
      if (f < 3) {
        EXPECT_GT(fs::file_size(image), 100u) << image;
      }
    }
  }
}

}  // namespace
}  // namespace vdmsim
