// docs/golden-images.md's CTest example, as it stands on the page: a project of the user's with
// a scene and its reference run passes its golden test, and fails it once the scene changes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The first ```cmake block of `page`.
std::string cmake_block(const std::string& page) {
  const size_t start = page.find("```cmake\n");
  if (start == std::string::npos) return "";
  const size_t body = start + 9, end = page.find("```", body);
  return page.substr(body, end - body);
}

// tests/golden/scenes/probe_small.yaml (four frames at 320x240) as my_scene, its mesh path made
// absolute, with `young_modulus`.
void write_scene(const fs::path& path, int young_modulus) {
  std::string scene = read(fs::path(VDMSIM_SOURCE_DIR) / "tests/golden/scenes/probe_small.yaml");
  scene = std::regex_replace(scene, std::regex("mesh: \\S+"),
                             "mesh: " + (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string());
  scene = std::regex_replace(scene, std::regex("name: \\S+"), "name: my_scene");
  scene = std::regex_replace(scene, std::regex("young_modulus: \\d+"), "young_modulus: " + std::to_string(young_modulus));
  fs::create_directories(path.parent_path());
  std::ofstream(path) << scene;
}

TEST(GoldenImagesDoc, TheCTestExamplePassesOnTheSameSceneAndFailsOnAChangedOne) {
  const std::string lists = cmake_block(read(fs::path(VDMSIM_SOURCE_DIR) / "docs/golden-images.md"));
  ASSERT_NE(lists.find("${VDMSIM} compare "), std::string::npos) << "no CTest example in docs/golden-images.md:\n" << lists;
  const fs::path project = vdmsim::test::scratch_dir("golden_images_doc") / "my_scenes";
  fs::remove_all(project);
  fs::create_directories(project);
  std::ofstream(project / "CMakeLists.txt") << lists;
  write_scene(project / "scenes/my_scene.yaml", 3000);

  const CliResult reference = vdmsim::test::run_cli(
      VDMSIM_BINARY, "run " + (project / "scenes/my_scene.yaml").string() + " --out " + (project / "expected/my_scene").string());
  ASSERT_EQ(reference.code, 0) << reference.output;
  const CliResult configure = vdmsim::test::run_cli(
      VDMSIM_CMAKE_COMMAND, "-S " + project.string() + " -B " + (project / "build").string() + " -DVDMSIM=" + VDMSIM_BINARY);
  ASSERT_EQ(configure.code, 0) << configure.output;

  const std::string ctest = VDMSIM_CTEST_COMMAND + std::string(" --test-dir ") + (project / "build").string() +
                            " --output-on-failure";
  const CliResult same = vdmsim::test::run_cli(ctest, "");
  EXPECT_EQ(same.code, 0) << same.output;
  EXPECT_NE(same.output.find("100% tests passed, 0 tests failed out of 2"), std::string::npos) << same.output;

  write_scene(project / "scenes/my_scene.yaml", 2000);
  const CliResult changed = vdmsim::test::run_cli(ctest, "");
  EXPECT_NE(changed.code, 0) << changed.output;
  EXPECT_NE(changed.output.find("frames/frame_00003.png: beyond tolerance"), std::string::npos) << changed.output;
  EXPECT_NE(changed.output.find("1 tests failed out of 2"), std::string::npos) << changed.output;
  EXPECT_TRUE(fs::exists(project / "build/out/my_scene_diff/frames/frame_00003.png"));
}

}  // namespace
