// docs/your-own-organ.md, followed as a new user would: its scene (the page's YAML block) is
// written to my_organ/my_liver.yaml, and every `./build/vdmsim` line of its bash blocks runs in
// order from a folder where `build` is the project's. Step 2's mesh-info must refuse the scan
// (exit 2), every other command must succeed; the numbers the page quotes are checked against
// what the commands print.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {
namespace fs = std::filesystem;

struct Page {
  std::vector<std::string> commands;
  std::string yaml;
};

Page read_page() {
  std::ifstream in(fs::path(VDMSIM_SOURCE_DIR) / "docs/your-own-organ.md");
  Page page;
  std::string line, block;
  bool code = false;
  while (std::getline(in, line)) {
    if (line.rfind("```", 0) == 0) {
      block = code ? "" : line.substr(3);
      code = !code;
      continue;
    }
    if (!code) continue;
    if (block == "bash" && line.rfind("./build/vdmsim ", 0) == 0) page.commands.push_back(line);
    if (block == "yaml") page.yaml += line + "\n";
  }
  return page;
}

std::string run(const fs::path& work, const std::string& cmd, int& code) {
  FILE* p = popen(("cd '" + work.string() + "' && " + cmd + " 2>&1").c_str(), "r");
  std::string output;
  char buf[4096];
  size_t n;
  while (p && (n = fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  code = p ? WEXITSTATUS(pclose(p)) : -1;
  return output;
}

TEST(YourOwnOrganDoc, TheTutorialRunsEndToEnd) {
  const fs::path work = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "your_own_organ";
  fs::remove_all(work);
  fs::create_directories(work / "my_organ");
  fs::create_directory_symlink(VDMSIM_BUILD_DIR, work / "build");
  const Page page = read_page();
  ASSERT_GE(page.commands.size(), 7u);
  ASSERT_NE(page.yaml.find("name: my_liver"), std::string::npos);
  std::ofstream(work / "my_organ/my_liver.yaml") << page.yaml;
  std::string prepare_report, locate_output, check_output;
  for (const std::string& cmd : page.commands) {
    int code = -1;
    const std::string output = run(work, cmd, code);
    const bool refused = cmd.find("mesh-info my_organ/scan_liver.obj") != std::string::npos;
    EXPECT_EQ(code, refused ? 2 : 0) << cmd << "\n" << output;
    std::printf("%s: exit %d\n", cmd.c_str(), code);
    if (refused) {
      EXPECT_NE(output.find("--scale 0.001 makes it"), std::string::npos) << output;
      EXPECT_NE(output.find("valid organ: no"), std::string::npos) << output;
    }
    if (cmd.find(" prepare-mesh ") != std::string::npos) prepare_report = output;
    if (cmd.find(" locate ") != std::string::npos) locate_output = output;
    if (cmd.find(" check ") != std::string::npos) check_output = output;
  }
  EXPECT_NE(prepare_report.find("targets: smallest angle >= 20 deg met, volume within 2 % met, mean distance <= 1.5 mm met"),
            std::string::npos)
      << prepare_report;
  EXPECT_NE(prepare_report.find("prepared   10011 nodes"), std::string::npos) << prepare_report;  // as the page shows
  EXPECT_NE(locate_output.find("point: 0.05 0 0.0488382"), std::string::npos) << locate_output;
  EXPECT_NE(locate_output.find("normal: -0.0298858"), std::string::npos) << locate_output;
  // check's report, as the page shows it: no warning, the probe touching and 10 mm deep.
  EXPECT_EQ(check_output.find("warning"), std::string::npos) << check_output;
  EXPECT_NE(check_output.find("fixed:      1578 of 10011 nodes (15.8 %) on every axis"), std::string::npos) << check_output;
  EXPECT_NE(check_output.find("first touches the organ at t = 0.2667 s, deepest 10 mm"), std::string::npos)
      << check_output;
  // The keyframes placed on the surface: the point locate prints, the tip 10 mm along the normal.
  EXPECT_NE(check_output.find("script[1] (t = 0.5 s): tip 0.0503 0.0014 0.03894 m, 10 mm inside the surface point "
                              "0.05 0 0.04884 (outward normal -0.02989 -0.14 0.9897), axis along the inward normal"),
            std::string::npos)
      << check_output;
  // The pictures, framed on the probe's working area.
  // Frame 15 (t = 0.5 s), the deepest press, as the page shows it; frames: 31 is t = 0 to 1 s.
  EXPECT_TRUE(fs::exists(work / "out/my_liver/frames/frame_00015.png"));
  EXPECT_TRUE(fs::exists(work / "out/my_liver/stress/stress_00015.png"));
  EXPECT_TRUE(fs::exists(work / "out/my_liver/stress/stress_00030.png"));
  EXPECT_FALSE(fs::exists(work / "out/my_liver/stress/stress_00031.png"));
  EXPECT_TRUE(fs::exists(work / "out/my_liver/run.json"));
}

}  // namespace
