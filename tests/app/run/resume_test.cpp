// --resume: a run interrupted by Ctrl-C and resumed gives the same result as a run that was
// never interrupted: the same metrics (every column but the wall-clock step_ms), and
// byte-identical frame images and contact sheet.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>
#include <vector>

#include "app/scene/mesh_io.hpp"
#include "app/run/scene_run.hpp"
#include "engine/shapes.hpp"
#include "support/binary.hpp"
#include "support/run_outputs.hpp"

namespace fs = std::filesystem;

namespace {
using vdmsim::test::metrics_without_timing;
using vdmsim::test::read_file;

const fs::path kOut = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "resume";

int run_in_process(const std::string& scene, const fs::path& out, bool resume) {
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(scene, ps, problems));
  vdmsim::RunOptions opt;
  opt.out_dir = out.string();
  opt.resume = resume;
  opt.checkpoint_every = 7;
  std::ostringstream o, e;
  const int rc = vdmsim::run_scene(ps, opt, o, e, false);
  EXPECT_EQ(rc, 0) << e.str();
  return rc;
}

// `--resume` of `scene` into `out`, expected to be refused (exit 2): its messages.
std::string refused_resume(const std::string& scene, const fs::path& out) {
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(scene, ps, problems));
  vdmsim::RunOptions opt;
  opt.out_dir = out.string();
  opt.resume = true;
  opt.checkpoint_every = 7;
  std::ostringstream o, e;
  EXPECT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 2) << e.str();
  return e.str();
}
}  // namespace

TEST(Resume, AnInterruptedRunResumedEqualsAnUninterruptedOne) {
  const fs::path dir = kOut / "interrupted";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A probe pressing into the liver (contact, stress view with an automatic colour range).
  const std::string scene = (dir / "press.yaml").string();
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n  model: vdm\n"  // the state snapshot
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 60, dt: 0.05, effects: [contact, stress]}\n"
                          "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.07], "
                          "axis: [0, 0, -1]}, {t: 3, tip: [0.035, 0, 0.045]}]}\n"
                          "render: {width: 160, height: 120, views: [shaded, stress], hud_step_time: false}\n";
  const fs::path whole = dir / "whole", resumed = dir / "resumed";
  ASSERT_EQ(run_in_process(scene, whole, false), 0);

  // The same run through the binary, interrupted once a few frames exist.
  const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene, "--out", resumed.string()});
  ASSERT_NE(pid, 0);
  const int code = vdmsim::test::interrupt_once_exists(pid, resumed / "frames" / "frame_00010.png", 120);
  if (code == 0) GTEST_SKIP() << "the run finished before it could be interrupted";
  ASSERT_EQ(code, 130);
  ASSERT_NE(read_file(resumed / "run.json").find("interrupted"), std::string::npos);

  ASSERT_EQ(run_in_process(scene, resumed, true), 0);
  EXPECT_NE(read_file(resumed / "run.json").find("\"resumed_from_frame\""), std::string::npos);
  EXPECT_NE(read_file(resumed / "run.json").find("\"resumed_by\": \"state snapshot\""), std::string::npos);
  EXPECT_EQ(metrics_without_timing(whole / "metrics.csv"), metrics_without_timing(resumed / "metrics.csv"));
  for (int f = 0; f < 60; ++f)
    for (const char* view : {"frames/frame_", "stress/stress_"}) {
      char name[64];
      std::snprintf(name, sizeof name, "%s%05d.png", view, f);
      EXPECT_EQ(read_file(whole / name), read_file(resumed / name)) << name;
    }
  EXPECT_EQ(read_file(whole / "contact_sheet.png"), read_file(resumed / "contact_sheet.png"));
}

TEST(Resume, RefusesACheckpointOfAnotherScene) {
  fs::create_directories(kOut / "other");
  const std::string a = (kOut / "other" / "a.yaml").string(), b = (kOut / "other" / "b.yaml").string();
  const std::string body = std::string("organ: {mesh: ") + VDMSIM_SOURCE_DIR +
                           "/assets/meshes/liver_L4.obj}\nsimulation: {frames: 3, effects: []}\n";
  std::ofstream(a) << "name: a\n" << body;
  std::ofstream(b) << "name: b\n" << body;
  ASSERT_EQ(run_in_process(a, kOut / "other", false), 0);
  const std::string e = refused_resume(b, kOut / "other");
  EXPECT_NE(e.find("the scene file changed"), std::string::npos) << e;
}

// The checkpoint identifies every file the run loaded: an organ mesh changed after the run (here
// scaled, as a user re-exporting it in other units would) is named, and the resume refused.
TEST(Resume, RefusesWhenTheOrganMeshChanged) {
  const fs::path dir = kOut / "mesh_changed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path mesh = dir / "box.obj";
  std::string error;
  ASSERT_TRUE(vdmsim::save_obj(vdm::make_box(vdm::Vec3(0.1, 0.1, 0.05), 4, 4, 2), mesh.string(), "a box", error));
  const std::string scene = (dir / "box.yaml").string();
  std::ofstream(scene) << "name: box\norgan: {mesh: box.obj}\nsimulation: {frames: 3, effects: []}\n";
  ASSERT_EQ(run_in_process(scene, dir / "out", false), 0);
  ASSERT_TRUE(vdmsim::save_obj(vdm::make_box(vdm::Vec3(0.2, 0.2, 0.1), 4, 4, 2), mesh.string(), "a box", error));
  const std::string e = refused_resume(scene, dir / "out");
  EXPECT_NE(e.find("the organ mesh changed"), std::string::npos) << e;
  EXPECT_EQ(e.find("the scene file changed"), std::string::npos) << e;
}

// Determinism: the same scene twice gives the same metrics.csv (every column but the
// wall-clock step_ms, bit for bit as text) and byte-identical images.
TEST(Determinism, TheSameSceneTwiceGivesIdenticalMetricsAndFrames) {
  fs::create_directories(kOut / "twice");
  const std::string scene = (kOut / "twice" / "twice.yaml").string();
  std::ofstream(scene) << "name: twice\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 12, dt: 0.05, effects: [contact, grasp, stress]}\n"
                          "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.065], "
                          "axis: [0, 0, -1]}, {t: 0.6, tip: [0.035, 0, 0.045]}]}\n"
                          "  - {type: grasper, script: [{t: 0, tip: [-0.08, 0, 0.041], axis: [0, 0, -1], jaw: open},"
                          " {t: 0.1, jaw: closed}, {t: 0.6, tip: [-0.08, 0, 0.056]}]}\n"
                          "render: {width: 160, height: 120, views: [shaded, stress], hud_step_time: false}\n";
  ASSERT_EQ(run_in_process(scene, kOut / "twice" / "1", false), 0);
  ASSERT_EQ(run_in_process(scene, kOut / "twice" / "2", false), 0);
  EXPECT_EQ(metrics_without_timing(kOut / "twice" / "1" / "metrics.csv"),
            metrics_without_timing(kOut / "twice" / "2" / "metrics.csv"));
  for (int f = 0; f < 12; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "frames/frame_%05d.png", f);
    EXPECT_EQ(read_file(kOut / "twice" / "1" / name), read_file(kOut / "twice" / "2" / name)) << name;
  }
}

// A reference model (here mass_spring) keeps its own state: the colour-range first pass of a
// rendered run must not leave the main run starting where it ended.
TEST(Determinism, ARenderedRunAndAnUnrenderedRunOfAMassSpringOrganAgree) {
  const fs::path dir = kOut / "mass_spring";
  fs::create_directories(dir);
  // A small box (the mass-spring solve is slow on the liver), made by the project's own code.
  std::string error;
  ASSERT_TRUE(vdmsim::save_obj(vdm::make_box(vdm::Vec3(0.1, 0.1, 0.1), 4, 4, 4), (dir / "box.obj").string(), "box", error))
      << error;
  const std::string scene = (dir / "ms.yaml").string();
  std::ofstream(scene) << "name: ms\norgan:\n  mesh: box.obj\n  model: mass_spring\n"
                          "  material: {young_modulus: 3000, poisson_ratio: 0.45}\n"
                          "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.049]}}]\n"
                          "  prescribed: [{box: {min: [-1, -1, 0.049], max: [1, 1, 1]}, translate: [0, 0, -0.01], "
                          "t: [0, 0.5]}]\n"
                          "simulation: {frames: 5, dt: 0.1, effects: []}\n"
                          "render: {width: 96, height: 64, views: [stress], stress: {quantity: displacement}}\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::prepare_scene(scene, ps, problems)) << (problems.empty() ? "" : problems[0].text());
  for (bool render : {true, false}) {
    vdmsim::RunOptions opt;
    opt.out_dir = (dir / (render ? "rendered" : "plain")).string();
    opt.render = render;
    std::ostringstream o, e;
    ASSERT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 0) << e.str();
  }
  EXPECT_EQ(metrics_without_timing(dir / "rendered" / "metrics.csv"), metrics_without_timing(dir / "plain" / "metrics.csv"));
}

// A hard kill (no chance to write anything at the end) after periodic checkpoints: rows and
// images past the last checkpoint are left behind; --resume goes back to the checkpoint and
// the result still equals an uninterrupted run.
TEST(Resume, AfterAHardKillResumesFromTheLastPeriodicCheckpoint) {
  const fs::path dir = kOut / "killed";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (dir / "press.yaml").string();
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n  model: vdm\n"  // the state snapshot
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.012], "
                          "t: [0, 2]}]\n"
                          "simulation: {frames: 50, dt: 0.05, effects: [stress]}\n"
                          "render: {width: 160, height: 120, views: [shaded, stress], hud_step_time: false}\n";
  const fs::path whole = dir / "whole", resumed = dir / "resumed";
  ASSERT_EQ(run_in_process(scene, whole, false), 0);
  const pid_t pid =
      vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene, "--out", resumed.string(), "--checkpoint-every", "7"});
  ASSERT_NE(pid, 0);
  vdmsim::test::wait_for_file(resumed / "frames" / "frame_00017.png", 120);
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) GTEST_SKIP() << "the run finished before it could be killed";
  ASSERT_TRUE(fs::exists(resumed / "checkpoint.json")) << "no periodic checkpoint was written";
  // A copy without the state snapshot resumes by re-simulating up to the checkpoint.
  const fs::path replayed = dir / "replayed";
  fs::copy(resumed, replayed, fs::copy_options::recursive);
  ASSERT_TRUE(fs::remove(replayed / "state.bin"));
  // A copy whose state snapshot lost one byte's worth of bits is refused, not continued.
  const fs::path damaged = dir / "damaged";
  fs::copy(resumed, damaged, fs::copy_options::recursive);
  {
    std::string bytes = read_file(damaged / "state.bin");
    ASSERT_GT(bytes.size(), 100u);
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5a);
    std::ofstream(damaged / "state.bin", std::ios::binary) << bytes;
  }
  const std::string refused = refused_resume(scene, damaged);
  EXPECT_NE(refused.find("checksum"), std::string::npos) << refused;

  ASSERT_EQ(run_in_process(scene, resumed, true), 0);
  ASSERT_EQ(run_in_process(scene, replayed, true), 0);
  EXPECT_NE(read_file(resumed / "run.json").find("\"resumed_by\": \"state snapshot\""), std::string::npos);
  EXPECT_NE(read_file(replayed / "run.json").find("\"resumed_by\": \"re-simulation\""), std::string::npos);
  for (const fs::path& r : {resumed, replayed}) {
    EXPECT_EQ(metrics_without_timing(whole / "metrics.csv"), metrics_without_timing(r / "metrics.csv")) << r;
    for (int f = 0; f < 50; ++f)
      for (const char* view : {"frames/frame_", "stress/stress_"}) {
        char name[64];
        std::snprintf(name, sizeof name, "%s%05d.png", view, f);
        EXPECT_EQ(read_file(whole / name), read_file(r / name)) << r << ' ' << name;
      }
  }
}

// Issue 46: --resume checks what it continues. A run with --export-mesh is interrupted; copies of
// its folder, each spoilt one way, are resumed through the binary: every one is refused (exit 2)
// with its own message, and run.json stays as the interrupted run wrote it.
TEST(Resume, RefusesACheckpointOrExportThatDoesNotFitTheRun) {
  const fs::path dir = kOut / "does_not_fit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (dir / "press.yaml").string();
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.012], "
                          "t: [0, 2]}]\n"
                          "simulation: {frames: 400, dt: 0.05, effects: []}\n";
  const fs::path stopped = dir / "stopped";
  const std::string args = " --export-mesh --no-render --checkpoint-every 5";
  const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene, "--out", stopped.string(), "--export-mesh",
                                               "--no-render", "--checkpoint-every", "5"});
  ASSERT_NE(pid, 0);
  const int code = vdmsim::test::interrupt_once_exists(pid, stopped / "mesh" / "frame_00012.vtu", 120);
  if (code == 0) GTEST_SKIP() << "the run finished before it could be interrupted";
  ASSERT_EQ(code, 130);
  const std::string run_json = read_file(stopped / "run.json");
  ASSERT_NE(run_json.find("\"status\": \"interrupted\""), std::string::npos) << run_json;

  // A copy of the interrupted folder, changed by `spoil`, resumed: its exit code and messages.
  auto resume_copy = [&](const std::string& name, const std::function<void(const fs::path&)>& spoil) {
    const fs::path copy = dir / name;
    fs::copy(stopped, copy, fs::copy_options::recursive);
    spoil(copy);
    const vdmsim::test::CliResult r =
        vdmsim::test::run_cli(VDMSIM_BINARY, "run " + scene + " --out " + copy.string() + " --resume" + args);
    EXPECT_EQ(read_file(copy / "run.json"), run_json) << name;
    return r;
  };
  auto set_frame = [](const fs::path& copy, const std::string& frame) {
    const std::string text = read_file(copy / "checkpoint.json");
    const size_t at = text.find("\"frame\": ") + 9;
    std::ofstream(copy / "checkpoint.json") << text.substr(0, at) << frame << text.substr(text.find(',', at));
  };

  // The case: a frame far beyond the run's 400.
  vdmsim::test::CliResult r = resume_copy("beyond", [&](const fs::path& c) { set_frame(c, "999999"); });
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("checkpoint.json: frame 999999 of 400 frames does not fit this run's 400 frames (0 to 399)"),
            std::string::npos)
      << r.output;
  // The last frame, "complete", while run.json says interrupted.
  r = resume_copy("last", [&](const fs::path& c) { set_frame(c, "399"); });
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("says every frame (to 399) is done, but run.json says status interrupted with "),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("already complete"), std::string::npos) << r.output;
  // The export this resume extends deleted.
  r = resume_copy("no_mesh", [](const fs::path& c) { fs::remove_all(c / "mesh"); });
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("/mesh: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames this resume's --export-mesh extends are missing (frame 0 to "), std::string::npos)
      << r.output;
  // A run stopped before its first checkpoint: said so, not "run without --resume first".
  r = resume_copy("no_checkpoint", [](const fs::path& c) { fs::remove(c / "checkpoint.json"); });
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("stopped before its first checkpoint"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("run without --resume first"), std::string::npos) << r.output;
}

// The ground-truth files of a run that failed at frame 10 (the renderer made to fail there) and
// was resumed from its checkpoint at frame 6 are those of a run that never stopped: poses.csv
// drops the rows of the frames after the checkpoint and writes them again, once.
TEST(Resume, GroundTruthFilesOfAResumedRunEqualAnUninterruptedRuns) {
  const fs::path dir = kOut / "ground_truth";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (dir / "press.yaml").string();
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 12, dt: 0.05, effects: [contact]}\n"
                          "instruments:\n  - {type: probe, radius: 0.008, script: [{t: 0, tip: [0.035, 0, 0.07], "
                          "axis: [0, 0, -1]}, {t: 0.55, tip: [0.035, 0, 0.05]}]}\n"
                          "render: {width: 96, height: 64, views: [shaded, depth, segmentation, normals], hud: false}\n";
  const fs::path whole = dir / "whole", resumed = dir / "resumed";
  ASSERT_EQ(run_in_process(scene, whole, false), 0);
  {
    vdmsim::PreparedScene ps;
    std::vector<vdmsim::SceneProblem> problems;
    ASSERT_TRUE(vdmsim::prepare_scene(scene, ps, problems));
    vdmsim::RunOptions opt;
    opt.out_dir = resumed.string();
    opt.checkpoint_every = 7;
    opt.fail_render_at_frame = 10;
    std::ostringstream o, e;
    ASSERT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 1) << e.str();
  }
  const std::string cut = read_file(resumed / "poses.csv");
  EXPECT_EQ(std::count(cut.begin(), cut.end(), '\n'), 1 + 10 * 2) << "the header and frames 0 to 9";
  ASSERT_EQ(run_in_process(scene, resumed, true), 0);
  EXPECT_NE(read_file(resumed / "run.json").find("\"resumed_from_frame\": 7"), std::string::npos);
  EXPECT_EQ(read_file(whole / "poses.csv"), read_file(resumed / "poses.csv"));
  EXPECT_EQ(read_file(whole / "camera.json"), read_file(resumed / "camera.json"));
  EXPECT_EQ(metrics_without_timing(whole / "metrics.csv"), metrics_without_timing(resumed / "metrics.csv"));
  for (int f = 0; f < 12; ++f)
    for (const char* view : {"depth/depth_.npy", "segmentation/segmentation_.png", "normals/normals_.png"}) {
      char number[16];
      std::snprintf(number, sizeof number, "%05d", f);
      std::string name = view;
      name.insert(name.find('_') + 1, number);
      ASSERT_TRUE(fs::exists(resumed / name)) << name;
      EXPECT_EQ(read_file(whole / name), read_file(resumed / name)) << name;
    }
}

// A poses.csv cut short (edited, or damaged) cannot be extended: the resume is refused with
// exit 2, naming the file, and the file is left as it was.
TEST(Resume, RefusesAPosesFileWithFewerFramesThanTheCheckpoint) {
  const fs::path dir = kOut / "poses_damaged";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (dir / "press.yaml").string();
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "simulation: {frames: 10, dt: 0.05}\n"
                          "render: {width: 64, height: 48, views: [depth], hud: false}\n";
  {
    vdmsim::PreparedScene ps;
    std::vector<vdmsim::SceneProblem> problems;
    ASSERT_TRUE(vdmsim::prepare_scene(scene, ps, problems));
    vdmsim::RunOptions opt;
    opt.out_dir = dir.string();
    opt.checkpoint_every = 7;
    opt.fail_render_at_frame = 8;
    std::ostringstream o, e;
    ASSERT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 1) << e.str();
  }
  const std::string poses = read_file(dir / "poses.csv");
  size_t cut = 0;
  for (int line = 0; line < 4; ++line) cut = poses.find('\n', cut) + 1;  // the header and frames 0 to 2
  std::ofstream(dir / "poses.csv", std::ios::binary) << poses.substr(0, cut);
  const std::string e = refused_resume(scene, dir);
  EXPECT_NE(e.find("poses.csv: has 3 whole rows before frame 7 where the checkpoint needs 7"), std::string::npos) << e;
  EXPECT_EQ(read_file(dir / "poses.csv"), poses.substr(0, cut));
}
