// Ctrl-C during a run: the run stops after the current frame, exits 130, and everything
// written so far is complete and valid (every PNG decodes, metrics.csv has one row per frame
// that run.json counts), with run.json saying "interrupted".
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/png_io.hpp"

extern char** environ;
namespace fs = std::filesystem;

TEST(Interrupt, CtrlCStopsAfterTheCurrentFrameAndKeepsEverything) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "interrupt";
  fs::remove_all(out);
  fs::create_directories(out);
  // A long scene (shaded view only, so no colour-range first pass) pushing the liver down.
  const std::string scene = (out / "long_press.yaml").string();
  std::ofstream(scene) << "name: long_press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.01], "
                          "t: [0, 100]}]\n"
                          "simulation: {frames: 100000, dt: 0.01, effects: []}\n"
                          "render: {width: 160, height: 120, views: [shaded]}\n";
  std::vector<std::string> args = {VDMSIM_BINARY, "run", scene, "--out", out.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  ASSERT_EQ(posix_spawn(&pid, VDMSIM_BINARY, &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Wait until a few frames exist, then interrupt.
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(out / "frames" / "frame_00003.png") &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  if (!fs::exists(out / "frames" / "frame_00003.png")) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    FAIL() << "the run produced no frames";
  }
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);

  std::ifstream json(out / "run.json");
  std::stringstream text;
  text << json.rdbuf();
  const std::string js = text.str();
  EXPECT_NE(js.find("\"status\": \"interrupted\""), std::string::npos) << js;
  const size_t at = js.find("\"frames\": ");
  ASSERT_NE(at, std::string::npos);
  const int frames = std::stoi(js.substr(at + 10));
  EXPECT_GE(frames, 4);
  EXPECT_LT(frames, 100000);
  // One metrics row per completed frame, each complete.
  std::ifstream metrics(out / "metrics.csv");
  std::string line;
  int rows = -1;
  long columns = 0;
  while (std::getline(metrics, line)) {
    ++rows;
    const long commas = std::count(line.begin(), line.end(), ',');
    if (rows == 0) columns = commas;
    EXPECT_EQ(commas, columns) << line;
  }
  EXPECT_EQ(rows, frames);
  // Every frame image decodes; none is left half written.
  int images = 0;
  for (const auto& e : fs::directory_iterator(out / "frames")) {
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
    render::Image im;
    std::string error;
    EXPECT_TRUE(render::read_png(e.path().string(), im, error)) << error;
    ++images;
  }
  EXPECT_EQ(images, frames);
}
