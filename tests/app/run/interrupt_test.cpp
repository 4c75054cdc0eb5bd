// Ctrl-C during a run: the run stops after the current frame, exits 130, and everything
// written so far is complete and valid (every PNG decodes, metrics.csv has one row per frame
// that run.json counts), with run.json saying "interrupted". On a failure the program's own
// output and run.json are printed, and the folder (one per test process, so that two runs of
// the test at once do not share it) is kept.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/png_io.hpp"
#include "support/binary.hpp"

namespace fs = std::filesystem;

TEST(Interrupt, CtrlCStopsAfterTheCurrentFrameAndKeepsEverything) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "interrupt" / std::to_string(getpid());
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
  const fs::path log = out / "vdmsim.log";
  const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene, "--out", out.string()}, log.string());
  ASSERT_NE(pid, 0);
  // Wait until a few frames exist, then interrupt.
  vdmsim::test::wait_for_file(out / "frames" / "frame_00003.png", 120);
  if (!fs::exists(out / "frames" / "frame_00003.png")) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    std::stringstream said;
    said << std::ifstream(log).rdbuf();
    FAIL() << "the run produced no frames in " << out.string() << "; vdmsim said:\n" << said.str();
  }
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  std::stringstream said, text;
  said << std::ifstream(log).rdbuf();
  text << std::ifstream(out / "run.json").rdbuf();
  const std::string js = text.str();
  SCOPED_TRACE("in " + out.string() + "\nvdmsim said:\n" + said.str() + "run.json:\n" + js);
  ASSERT_TRUE(WIFEXITED(status)) << "vdmsim ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 130);

  EXPECT_NE(js.find("\"status\": \"interrupted\""), std::string::npos);
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
  if (!HasFailure()) fs::remove_all(out);
}
