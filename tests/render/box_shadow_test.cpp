// A box probe casts the shadow of a box: turned a quarter about its own axis (out of view, above
// the organ), its shadow on the organ changes; without shadows the pictures are the same.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/run/scene_run.hpp"
#include "render/image_compare.hpp"
#include "render/png_io.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kShadowOut = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "box_shadow";

// Frame 0 of a 40 x 8 x 30 mm box probe held 8 cm above the right lobe, its long side along
// `long_axis` (x or y), seen from low at the side so that the probe is out of the picture.
render::Image render_box(const std::string& tag, const char* size, bool shadows) {
  fs::create_directories(kShadowOut);
  const fs::path scene = kShadowOut / (tag + ".yaml");
  std::ofstream(scene) << "name: " << tag << "\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "simulation: {frames: 1, dt: 0.1, effects: []}\n"
                          "instruments:\n  - type: probe\n    shape: {type: box, size: "
                       << size
                       << "}\n    script: [{t: 0, tip: [0.0, -0.045, 0.125], axis: [0, 0, -1]}]\n"
                          "render: {width: 200, height: 150, views: [shaded], hud: false, floor: false, shadows: "
                       << (shadows ? "true" : "false")
                       << ",\n         camera: {eye: [0.17, -0.12, 0.1], target: [0.035, 0.0, 0.05], fov_deg: 30}}\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(scene.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = (kShadowOut / tag).string();
  std::ostringstream o, e;
  EXPECT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 0) << e.str();
  render::Image im;
  std::string error;
  EXPECT_TRUE(render::read_png((kShadowOut / tag / "frames" / "frame_00000.png").string(), im, error)) << error;
  return im;
}

}  // namespace

TEST(BoxShadow, TurningABoxProbeChangesItsShadowOnly) {
  const render::Image along_x = render_box("along_x", "[0.04, 0.008, 0.03]", true);
  const render::Image along_y = render_box("along_y", "[0.008, 0.04, 0.03]", true);
  const render::CompareResult shadows = render::compare_images(along_x, along_y, {8, 0.0}, nullptr);
  EXPECT_GT(shadows.differing_share, 0.002) << shadows.summary();
  // Without shadows the two pictures are the same: the probe itself is out of view.
  const render::Image plain_x = render_box("plain_x", "[0.04, 0.008, 0.03]", false);
  const render::Image plain_y = render_box("plain_y", "[0.008, 0.04, 0.03]", false);
  const render::CompareResult plain = render::compare_images(plain_x, plain_y, {0, 0.0}, nullptr);
  EXPECT_TRUE(plain.match) << plain.summary();
  // And the shadow darkens the organ: the shadowed picture differs from the plain one.
  EXPECT_GT(render::compare_images(along_x, plain_x, {8, 0.0}, nullptr).differing_share, 0.002);
}
