// A write error mid-run (here: a file-size limit, which fails writes the way a full disk
// does): a clear message, the run stops with status failed, and everything written before is
// intact (every frame image decodes, every metrics row is whole, run.json is valid).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "render/png_io.hpp"

namespace fs = std::filesystem;

namespace {

// Runs `vdmsim run SCENE --out RUN [--no-render]` in a child process whose files may not grow
// past `limit` bytes (a disk that fills up), its stderr to DIR/stderr.txt; returns its exit
// status, -1 when it did not exit.
int run_on_a_full_disk(const std::string& scene, const fs::path& run, const fs::path& dir, rlim_t limit,
                       bool render = true) {
  const pid_t pid = fork();
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    rlimit lim{limit, limit};
    setrlimit(RLIMIT_FSIZE, &lim);
    const std::string log = (dir / "stderr.txt").string();
    freopen(log.c_str(), "w", stderr);
    freopen("/dev/null", "w", stdout);
    execl(VDMSIM_BINARY, VDMSIM_BINARY, "run", scene.c_str(), "--out", run.string().c_str(),
          render ? (char*)nullptr : "--no-render", (char*)nullptr);
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The frames a failed run's run.json counts (it must say the run failed); -1 without a count.
int frames_of_a_failed_run(const fs::path& run) {
  std::stringstream js;
  js << std::ifstream(run / "run.json").rdbuf();
  EXPECT_NE(js.str().find("\"status\": \"failed\""), std::string::npos) << js.str();
  const size_t at = js.str().find("\"frames\": ");
  EXPECT_NE(at, std::string::npos) << js.str();
  return at == std::string::npos ? -1 : std::stoi(js.str().substr(at + 10));
}

}  // namespace

TEST(WriteError, AFullDiskStopsTheRunCleanlyAndKeepsEarlierFrames) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "write_error";
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string scene = (out / "long.yaml").string();
  std::ofstream(scene) << "name: long\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.01], "
                          "t: [0, 10]}]\n"
                          "simulation: {frames: 400, dt: 0.01, effects: []}\n"
                          "render: {width: 96, height: 64, views: [shaded], hud: false}\n";
  const fs::path run = out / "run";
  // Files may not grow past 24 kB: metrics.csv reaches it after about 150 rows.
  EXPECT_EQ(run_on_a_full_disk(scene, run, out, 24000), 1);
  std::stringstream err;
  err << std::ifstream(out / "stderr.txt").rdbuf();
  EXPECT_NE(err.str().find("metrics.csv"), std::string::npos) << err.str();
  const int frames = frames_of_a_failed_run(run);
  EXPECT_GT(frames, 20);
  EXPECT_LT(frames, 400);
  // Every row before the failure is whole; every image of those frames decodes.
  std::ifstream metrics(run / "metrics.csv");
  std::string line;
  int rows = -1;
  long columns = -1;
  while (std::getline(metrics, line)) {
    const long commas = std::count(line.begin(), line.end(), ',');
    if (rows < 0) columns = commas;
    EXPECT_EQ(commas, columns) << "row " << rows;
    ++rows;
  }
  EXPECT_EQ(rows, frames);  // one whole row per completed frame, no half row
  for (int f = 0; f < frames; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%05d.png", f);
    render::Image im;
    std::string error;
    EXPECT_TRUE(render::read_png((run / "frames" / name).string(), im, error)) << error;
  }
}

// Issue 31: a disk that fills up before the 30th frame (the first periodic checkpoint) left
// nothing to resume and a 0-byte run.json.tmp. Now the first checkpoint follows the first
// frame, a write that fails leaves no .tmp behind, and the run resumes to the end.
TEST(WriteError, AFullDiskEarlyLeavesAResumableRunAndNoTmpFile) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "write_error_early";
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string scene = (out / "early.yaml").string();
  std::ofstream(scene) << "name: early\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.01], "
                          "t: [0, 0.4]}]\n"
                          "simulation: {frames: 40, dt: 0.01, effects: []}\n";
  const fs::path run = out / "run";
  // Files may not grow past 700 bytes: metrics.csv reaches it after a few rows, run.json (900
  // bytes) cannot be written at all; checkpoint.json (300 bytes) fits.
  EXPECT_EQ(run_on_a_full_disk(scene, run, out, 700, false), 1);
  std::stringstream err;
  err << std::ifstream(out / "stderr.txt").rdbuf();
  EXPECT_NE(err.str().find("metrics.csv"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("run.json"), std::string::npos) << err.str();
  for (const auto& entry : fs::directory_iterator(run))
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path() << " left behind";
  ASSERT_TRUE(fs::exists(run / "checkpoint.json")) << err.str();
  // With room again, the run continues from its checkpoint to the end.
  const std::string resume = std::string(VDMSIM_BINARY) + " run " + scene + " --out " + run.string() + " --no-render --resume";
  EXPECT_EQ(std::system((resume + " > " + (out / "resume.txt").string() + " 2>&1").c_str()), 0);
  std::stringstream js;
  js << std::ifstream(run / "run.json").rdbuf();
  EXPECT_NE(js.str().find("\"status\": \"completed\""), std::string::npos) << js.str();
  EXPECT_NE(js.str().find("\"frames\": 40"), std::string::npos) << js.str();
}

// poses.csv filling the disk first (it grows fastest here: a camera row and a probe row per
// frame): the run stops with the file named, and every frame it counts is whole everywhere: a
// metrics row, a camera and a probe row in poses.csv, its depth and segmentation files.
TEST(WriteError, AFullDiskUnderPosesCsvKeepsWholeFramesInEveryFile) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "write_error_poses";
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string scene = (out / "poses.yaml").string();
  std::ofstream(scene) << "name: poses\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 400, dt: 0.01, effects: []}\n"
                          "instruments:\n  - {type: probe, radius: 0.004, script: [{t: 0, tip: [0.0311, 0.0017, 0.1234], "
                          "axis: [0.1, 0.2, -1]}, {t: 4, tip: [0.0511, -0.0213, 0.1571]}]}\n"
                          "render: {width: 32, height: 24, views: [depth, segmentation]}\n";
  const fs::path run = out / "run";
  // Files may not grow past 24 kB: poses.csv reaches it first, after about 100 frames.
  EXPECT_EQ(run_on_a_full_disk(scene, run, out, 24000), 1);
  std::stringstream err;
  err << std::ifstream(out / "stderr.txt").rdbuf();
  EXPECT_NE(err.str().find("poses.csv: write failed"), std::string::npos) << err.str();
  const int frames = frames_of_a_failed_run(run);
  EXPECT_GT(frames, 20);
  EXPECT_LT(frames, 400);
  auto whole_rows = [](const fs::path& csv, long& columns) {
    std::ifstream in(csv);
    std::string line;
    int rows = -1;
    columns = -1;
    while (std::getline(in, line)) {
      const long commas = std::count(line.begin(), line.end(), ',');
      if (rows < 0) columns = commas;
      EXPECT_EQ(commas, columns) << csv << " row " << rows;
      ++rows;
    }
    return rows;
  };
  long columns = 0;
  EXPECT_EQ(whole_rows(run / "metrics.csv", columns), frames);
  EXPECT_EQ(whole_rows(run / "poses.csv", columns), 2 * frames);
  EXPECT_EQ(columns, 14);
  for (int f = 0; f < frames; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "segmentation_%05d.png", f);
    render::Image im;
    std::string error;
    EXPECT_TRUE(render::read_png((run / "segmentation" / name).string(), im, error)) << error;
    std::snprintf(name, sizeof name, "depth_%05d.npy", f);
    EXPECT_EQ(fs::file_size(run / "depth" / name), 128u + 32 * 24 * 4) << name;
  }
}
