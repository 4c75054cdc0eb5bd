// --resume of runs of the default organ model, vdm_core (the elastic core). A run interrupted by
// Ctrl-C resumes from its state snapshot (run.json: resumed_by "state snapshot"), not by
// re-simulating the frames before it, and gives the same metrics.csv (but step_ms) and
// byte-identical images and contact sheet as a run never stopped: a probe pressing and sliding
// with friction (the default constraint contact), and a grasper holding tissue across the
// checkpoint. Without state.bin the resume re-simulates to the same result; a damaged
// state.bin, or one whose core snapshot is cut under a valid checksum, is refused.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/run/checkpoint.hpp"
#include "app/run/scene_run.hpp"
#include "support/binary.hpp"
#include "support/run_outputs.hpp"

namespace fs = std::filesystem;

namespace {
using vdmsim::test::metrics_without_timing;
using vdmsim::test::read_file;

const fs::path kOut = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "core_resume";
constexpr int kFrames = 40;

// The liver on the default model, its base fixed, with `instruments` and `effects`; 40 frames
// drawn small in the shaded and stress views (the stress view's range found by a first pass).
std::string liver_scene(const std::string& effects, const std::string& instruments) {
  return std::string("name: core_resume\norgan:\n  mesh: ") + VDMSIM_SOURCE_DIR + "/assets/meshes/liver_L4.obj\n" +
         "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n" +
         "simulation: {frames: " + std::to_string(kFrames) + ", dt: 0.05, effects: " + effects + "}\n" + instruments +
         "render: {width: 128, height: 96, views: [shaded, stress], hud_step_time: false}\n";
}

// A probe that presses into the liver, then slides along it.
const std::string kPressAndSlide = liver_scene(
    "[contact, stress]", "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.062], "
                         "axis: [0, 0, -1]}, {t: 0.6, tip: [0.035, 0, 0.05]}, {t: 1.9, tip: [0.05, 0, 0.05]}]}\n");

// A grasper that closes on the liver's right lobe at t = 0.1 s (frame 2) and lifts it 3 cm.
const std::string kGraspAndLift = liver_scene(
    "[contact, grasp, stress]",
    "instruments:\n  - {type: grasper, radius: 0.005, jaw_length: 0.015, grasp_width: 0.006, script: ["
    "{t: 0, tip: [0.035, 0, 0.0603], axis: [0, 0, -1], jaw: open}, {t: 0.1, jaw: closed},"
    " {t: 1.9, tip: [0.035, 0, 0.0903]}]}\n");

// Runs the scene file in this process into `out`; its exit code (and messages, in `err`).
int run_in_process(const std::string& scene, const fs::path& out, bool resume, std::string* err = nullptr) {
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(scene, ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = out.string();
  opt.resume = resume;
  std::ostringstream o, e;
  const int rc = vdmsim::run_scene(ps, opt, o, e, false);
  if (err) *err = e.str();
  return rc;
}

// The frame run.json says the resume started from (-1 when it says none).
int resumed_from(const fs::path& dir) {
  const std::string js = read_file(dir / "run.json");
  const size_t at = js.find("\"resumed_from_frame\": ");
  return at == std::string::npos ? -1 : std::stoi(js.substr(at + 22));
}

class CoreResume : public ::testing::Test {
 protected:
  // Writes `yaml` as the scene, runs it whole into dir/whole, and through the binary into
  // dir/stopped, interrupted by Ctrl-C once frame 10's image is on disk. False when that run
  // finished before it could be interrupted (the test is then skipped).
  bool run_whole_and_interrupted(const std::string& name, const std::string& yaml) {
    dir_ = kOut / name;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    scene_ = (dir_ / "scene.yaml").string();
    std::ofstream(scene_) << yaml;
    std::string err;
    EXPECT_EQ(run_in_process(scene_, dir_ / "whole", false, &err), 0) << err;
    const fs::path stopped = dir_ / "stopped";
    const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene_, "--out", stopped.string()});
    EXPECT_NE(pid, 0);
    const int code = vdmsim::test::interrupt_once_exists(pid, stopped / "frames" / "frame_00010.png", 120);
    if (code == 0) return false;
    EXPECT_EQ(code, 130);
    EXPECT_NE(read_file(stopped / "run.json").find("\"status\": \"interrupted\""), std::string::npos);
    EXPECT_TRUE(fs::exists(stopped / "state.bin")) << "the interrupted run saved its state";
    return true;
  }

  // A copy of the interrupted run's folder, resumed in this process: its exit code and messages.
  int resume_copy(const std::string& name, std::string& err, void (*spoil)(const fs::path&) = nullptr) {
    const fs::path copy = dir_ / name;
    fs::copy(dir_ / "stopped", copy, fs::copy_options::recursive);
    if (spoil) spoil(copy);
    return run_in_process(scene_, copy, true, &err);
  }

  // The resumed run in `name` equals the uninterrupted one: metrics (but step_ms), every
  // image, the contact sheet.
  void expect_same_as_whole(const std::string& name) {
    const fs::path whole = dir_ / "whole", resumed = dir_ / name;
    EXPECT_EQ(metrics_without_timing(whole / "metrics.csv"), metrics_without_timing(resumed / "metrics.csv")) << name;
    for (int f = 0; f < kFrames; ++f)
      for (const char* view : {"frames/frame_", "stress/stress_"}) {
        char file[64];
        std::snprintf(file, sizeof file, "%s%05d.png", view, f);
        EXPECT_EQ(read_file(whole / file), read_file(resumed / file)) << name << ' ' << file;
      }
    EXPECT_EQ(read_file(whole / "contact_sheet.png"), read_file(resumed / "contact_sheet.png")) << name;
  }

  bool resumed_by_snapshot(const std::string& name) {
    return read_file(dir_ / name / "run.json").find("\"resumed_by\": \"state snapshot\"") != std::string::npos;
  }

  fs::path dir_;
  std::string scene_;
};

TEST_F(CoreResume, AnInterruptedPressWithFrictionResumesFromItsSnapshot) {
  if (!run_whole_and_interrupted("press", kPressAndSlide)) GTEST_SKIP() << "the run finished before it could be interrupted";
  std::string err;
  ASSERT_EQ(resume_copy("resumed", err), 0) << err;
  EXPECT_TRUE(resumed_by_snapshot("resumed")) << read_file(dir_ / "resumed" / "run.json");
  EXPECT_GE(resumed_from(dir_ / "resumed"), 11);
  expect_same_as_whole("resumed");
  // Without the snapshot the frames before the checkpoint are simulated again: the same run.
  ASSERT_EQ(resume_copy("replayed", err, [](const fs::path& c) { fs::remove(c / "state.bin"); }), 0) << err;
  EXPECT_NE(read_file(dir_ / "replayed" / "run.json").find("\"resumed_by\": \"re-simulation\""), std::string::npos);
  expect_same_as_whole("replayed");
}

TEST_F(CoreResume, AnInterruptedGraspResumesFromItsSnapshotWhileItHolds) {
  if (!run_whole_and_interrupted("grasp", kGraspAndLift)) GTEST_SKIP() << "the run finished before it could be interrupted";
  std::string err;
  ASSERT_EQ(resume_copy("resumed", err), 0) << err;
  EXPECT_TRUE(resumed_by_snapshot("resumed")) << read_file(dir_ / "resumed" / "run.json");
  EXPECT_GT(resumed_from(dir_ / "resumed"), 2) << "the jaws had closed before the checkpoint";
  expect_same_as_whole("resumed");
}

TEST_F(CoreResume, ADamagedOrCutStateFileIsRefused) {
  if (!run_whole_and_interrupted("damaged", kPressAndSlide)) GTEST_SKIP() << "the run finished before it could be interrupted";
  std::string err;
  // A byte's bits flipped: the checksum says so.
  EXPECT_EQ(resume_copy("flipped", err,
                        [](const fs::path& c) {
                          std::string bytes = read_file(c / "state.bin");
                          bytes[bytes.size() / 3] = static_cast<char>(bytes[bytes.size() / 3] ^ 0x5a);
                          std::ofstream(c / "state.bin", std::ios::binary) << bytes;
                        }),
            2);
  EXPECT_NE(err.find("checksum"), std::string::npos) << err;
  // The core's snapshot cut short, in a file whose checksum is right: the core's own checks.
  EXPECT_EQ(resume_copy("cut", err,
                        [](const fs::path& c) {
                          vdmsim::StateFile sf;
                          std::string error;
                          ASSERT_TRUE(vdmsim::read_state_file((c / "state.bin").string(), sf, error)) << error;
                          sf.snapshot.resize(200);
                          ASSERT_TRUE(vdmsim::write_state_file((c / "state.bin").string(), sf, error)) << error;
                        }),
            2);
  EXPECT_NE(err.find("state snapshot: the elastic core's state is truncated"), std::string::npos) << err;
  EXPECT_NE(err.find("cannot resume"), std::string::npos) << err;
}

}  // namespace
