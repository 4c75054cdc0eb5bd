// Instrument mesh skins: loaded through the mesh loader, placed in the instrument frame, drawn
// instead of the parametric shape; a missing skin file is a scene error with its position.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/scene/mesh_io.hpp"
#include "app/run/scene_run.hpp"
#include "engine/shapes.hpp"
#include "render/image_compare.hpp"
#include "render/png_io.hpp"

namespace fs = std::filesystem;

namespace {
const fs::path kSkinOut = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "skins";

// A probe scene whose instrument may carry `skin_yaml`; returns frame 0 of its render.
render::Image render_probe(const std::string& tag, const std::string& skin_yaml) {
  fs::create_directories(kSkinOut);
  const fs::path scene = kSkinOut / (tag + ".yaml");
  std::ofstream(scene) << "name: " << tag << "\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "simulation: {frames: 1, dt: 0.1, effects: []}\n"
                          "instruments:\n  - type: probe\n    radius: 0.01\n"
                       << skin_yaml
                       << "    script: [{t: 0, tip: [0.035, 0, 0.09], axis: [0, 0, -1]}]\n"
                          "render: {width: 160, height: 120, views: [shaded], hud: false,\n"
                          "         camera: {eye: [0.2, -0.2, 0.15], target: [0.035, 0, 0.08]}}\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(scene.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = (kSkinOut / tag).string();
  std::ostringstream o, e;
  EXPECT_EQ(vdmsim::run_scene(ps, opt, o, e, false), 0) << e.str();
  render::Image im;
  std::string error;
  EXPECT_TRUE(render::read_png((kSkinOut / tag / "frames" / "frame_00000.png").string(), im, error)) << error;
  return im;
}
}  // namespace

// A skin (here a 6 cm cube made by the project's own shape code) replaces the capsule: the
// picture changes where the instrument is and nowhere else.
TEST(InstrumentSkin, AMeshSkinReplacesTheParametricProbe) {
  fs::create_directories(kSkinOut);
  const vdm::SurfaceMesh box = vdm::make_box(vdm::Vec3(60, 60, 60), 1, 1, 1);  // mm
  std::string error;
  ASSERT_TRUE(vdmsim::save_obj(box, (kSkinOut / "cube_skin.obj").string(), "test skin", error)) << error;
  const render::Image plain = render_probe("plain", "");
  const render::Image skinned =
      render_probe("skinned", "    skin: {body: cube_skin.obj, scale: 0.001, origin: [0, 0, -0.03]}\n");
  const render::CompareResult r = render::compare_images(plain, skinned, {8, 0.0}, nullptr);
  EXPECT_FALSE(r.match);
  EXPECT_GT(r.differing_share, 0.01) << r.summary();  // the cube is much bigger than the probe
  EXPECT_LT(r.differing_share, 0.5) << r.summary();
}

TEST(InstrumentSkin, AMissingSkinFileIsASceneErrorWithItsPosition) {
  fs::create_directories(kSkinOut);
  const fs::path scene = kSkinOut / "missing_skin.yaml";
  std::ofstream(scene) << "organ: {mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj}\n"
                          "instruments:\n  - type: probe\n    skin: {body: no_such_skin.stl}\n"
                          "    script: [{t: 0, tip: [0, 0, 0.1]}]\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_FALSE(vdmsim::prepare_scene(scene.string(), ps, problems));
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems[0].field, "instruments[0].skin.body");
  EXPECT_NE(problems[0].where.find("missing_skin.yaml:4:"), std::string::npos) << problems[0].where;
  EXPECT_NE(problems[0].message.find("no_such_skin.stl"), std::string::npos) << problems[0].message;
}

// The shared Maryland dissector (third-party STL, tests only) as a grasper's shaft and jaws.
TEST(InstrumentSkin, SharedMarylandDissectorSkinRenders) {
  const fs::path assets = fs::path(VDMSIM_SOURCE_DIR) / ".." / "shared" / "assets" / "instruments";
  if (!fs::exists(assets / "maryland_dissector_jaw_left.stl")) GTEST_SKIP() << "../shared/assets absent: skipped";
  const std::string a = assets.string();
  const render::Image plain = render_probe("plain_grasper", "");
  const render::Image skinned = render_probe(
      "maryland", "    skin: {body: " + a + "/instrument_shaft.stl, jaws: [" + a + "/maryland_dissector_jaw_left.stl, " + a +
                      "/maryland_dissector_jaw_right.stl], scale: 0.001, origin: [0, 0, -0.02]}\n");
  EXPECT_FALSE(render::compare_images(plain, skinned, {8, 0.0}, nullptr).match);
}
