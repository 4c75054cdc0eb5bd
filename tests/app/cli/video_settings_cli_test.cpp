// Issue 31: video settings that ffmpeg cannot use (a '%' in --out, an absurd frame rate) are
// refused before the first frame is simulated, not after every frame has been rendered.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

fs::path video_settings_dir() { return vdmsim::test::scratch_dir("video_settings_cli"); }

std::string video_scene(const std::string& name, const std::string& render) {
  const fs::path p = video_settings_dir() / name;
  std::ofstream(p) << "name: video\norgan:\n  mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "\nsimulation: {frames: 3}\nrender: {width: 64, height: 48" << render << "}\n";
  return p.string();
}

TEST(VideoSettingsCli, PercentInOutIsRefusedBeforeSimulating) {
  const fs::path out = video_settings_dir() / "run_%d";
  const auto r = vdmsim::test::run_cli(VDMSIM_BINARY, "run " + video_scene("ok.yaml", "") + " --video --out '" + out.string() + "'");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--out " + out.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("may not contain '%'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "frames")) << "frames were rendered first";
  EXPECT_FALSE(fs::exists(out / "metrics.csv"));
}

TEST(VideoSettingsCli, AbsurdFrameRatesAreRefusedAtCheck) {
  for (const char* fps : {"1e-300", "0.5", "1001", "1e300"}) {
    const std::string p = video_scene("fps.yaml", std::string(", fps: ") + fps);
    const auto r = vdmsim::test::run_cli(VDMSIM_BINARY, "check " + p);
    EXPECT_EQ(r.code, 2) << fps << ": " << r.output;
    EXPECT_NE(r.output.find(p), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("render.fps"), std::string::npos) << r.output;
  }
  const auto ok = vdmsim::test::run_cli(VDMSIM_BINARY, "check " + video_scene("fps_ok.yaml", ", fps: 24"));
  EXPECT_EQ(ok.code, 0) << ok.output;
}

}  // namespace
