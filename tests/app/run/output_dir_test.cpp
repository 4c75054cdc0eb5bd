// The output folder is owned by one run: a second run into a folder in use is refused (exit 2)
// and writes nothing there; a fresh run removes the earlier run's summary first; a scene name
// becomes a folder name that cannot leave out/.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// One folder per test, in the test process's scratch folder (support/scratch_dir.hpp).
fs::path test_dir() {
  const fs::path d = test::scratch_dir("output_dir") / ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(d);
  return d;
}

std::string write_scene(const fs::path& dir) {
  const fs::path p = dir / "scene.yaml";
  std::ofstream(p) << "name: owned\norgan: {mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "}\nsimulation: {frames: 2, effects: []}\n";
  return p.string();
}

int run(const std::string& scene, const fs::path& out, std::string& messages) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_TRUE(prepare_scene(scene, ps, problems));
  RunOptions opt;
  opt.out_dir = out.string();
  std::ostringstream o, e;
  const int code = run_scene(ps, opt, o, e, false);
  messages = e.str();
  return code;
}

TEST(OutputDir, ASecondRunIntoAFolderInUseIsRefused) {
  const fs::path dir = test_dir();
  const std::string scene = write_scene(dir);
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::string messages, error;
  {
    OutputLock held;  // another run, still going
    ASSERT_TRUE(held.acquire(out, error)) << error;
    EXPECT_EQ(run(scene, out, messages), 2);
    EXPECT_NE(messages.find("in use by another vdmsim run (process "), std::string::npos) << messages;
    EXPECT_FALSE(fs::exists(out / "metrics.csv"));
    EXPECT_FALSE(fs::exists(out / "run.json"));
  }
  EXPECT_EQ(run(scene, out, messages), 0) << messages;  // released with its owner
  EXPECT_TRUE(fs::exists(out / "run.json"));
}

// A fresh run killed before it writes its own run.json leaves none: not the earlier run's summary
// beside the new run's frames.
TEST(OutputDir, AFreshRunRemovesTheEarlierSummaryFirst) {
  const fs::path dir = test_dir();
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "run.json") << "{\"scene\": \"another\"}\n";
  const fs::path scene = dir / "long.yaml";
  std::ofstream(scene) << "name: long\norgan: {mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L5.obj").string()
                       << "}\nsimulation: {frames: 2000, effects: [stress]}\n";
  const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene.string(), "--out", out.string()});
  ASSERT_NE(pid, 0);
  vdmsim::test::wait_for_file(out / "metrics.csv", 60);
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) GTEST_SKIP() << "the run finished before it could be killed";
  EXPECT_TRUE(fs::exists(out / "metrics.csv"));
  EXPECT_FALSE(fs::exists(out / "run.json"));
}

TEST(OutputDir, SceneNamesBecomeFolderNamesInsideOut) {
  EXPECT_EQ(safe_folder_name("probe_poke"), "probe_poke");
  EXPECT_EQ(safe_folder_name("liver v2.1"), "liver_v2.1");
  EXPECT_EQ(safe_folder_name("../../etc"), "_.._etc");
  EXPECT_EQ(safe_folder_name("/abs/path"), "_abs_path");
  EXPECT_EQ(safe_folder_name(".."), "scene");
  EXPECT_EQ(safe_folder_name(""), "scene");
  EXPECT_EQ(safe_folder_name("foie_gras_é"), "foie_gras___");
  for (const std::string name : {"../../etc", "/abs/path", "..", "a/../../b"}) {
    const fs::path p = fs::path("out") / safe_folder_name(name);
    EXPECT_EQ(p.parent_path(), fs::path("out")) << name;
    EXPECT_EQ(p.lexically_normal().parent_path(), fs::path("out")) << name;
  }
}

}  // namespace
}  // namespace vdmsim
