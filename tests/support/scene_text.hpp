#pragma once
// A scene given as text, prepared as `vdmsim run` prepares it: written into a folder of the
// build tree named for the test file's `suite` and the running test, so that a failing test's
// scene can be read afterwards.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/simulation/prepared_scene.hpp"

namespace vdmsim::test {

inline std::filesystem::path test_output_dir(const std::string& suite) {
  const std::filesystem::path d = std::filesystem::path(VDMSIM_BUILD_DIR) / "test-output" / suite /
                                  ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::filesystem::create_directories(d);
  return d;
}

inline PreparedScene prepare_scene_text(const std::string& suite, const std::string& text) {
  const std::filesystem::path p = test_output_dir(suite) / "scene.yaml";
  std::ofstream(p) << text;
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  return ps;
}

}  // namespace vdmsim::test
