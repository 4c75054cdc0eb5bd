// render.views: each name a row of the view table (render/views.hpp), kept in the table's order
// once each; an unknown name is an error at its file:line:col naming the field, the known
// views and the closest one; `vdmsim check` exits 2 on it, and `run --video` with ground-truth
// views only is refused before anything runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/scene/scene.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

std::string views_scene(const std::string& name, const std::string& render, const std::string& instruments = "") {
  const fs::path p = vdmsim::test::scratch_dir("scene_views") / name;
  std::ofstream(p) << "name: views\norgan:\n  mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "\n  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\nsimulation: {frames: 2, dt: 0.04}\n"
                   << instruments << render;
  return p.string();
}

}  // namespace

TEST(SceneViews, TheViewsAreKeptInTheTablesOrderOnceEach) {
  using render::View;
  const vdmsim::SceneLoadResult r =
      vdmsim::load_scene(views_scene("order.yaml", "render:\n  views: [normals, depth, shaded, depth, segmentation]\n"));
  ASSERT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0].text());
  EXPECT_EQ(r.scene.render.views, (std::vector<View>{View::shaded, View::depth, View::segmentation, View::normals}));
  EXPECT_TRUE(r.scene.render.has_ground_truth());
  EXPECT_TRUE(r.scene.render.has_picture());
  const vdmsim::SceneLoadResult plain = vdmsim::load_scene(views_scene("default.yaml", "render: {width: 64}\n"));
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain.scene.render.views, std::vector<View>{View::shaded});
  EXPECT_FALSE(plain.scene.render.has_ground_truth());
  const vdmsim::SceneLoadResult depth_only = vdmsim::load_scene(views_scene("depth.yaml", "render: {views: [depth]}\n"));
  ASSERT_TRUE(depth_only.ok());
  EXPECT_FALSE(depth_only.scene.render.has_picture());
}

TEST(SceneViews, AnUnknownViewIsAnErrorAtItsLineAndColumn) {
  const std::string path = views_scene("unknown.yaml", "render:\n  views: [shaded, dept]\n");
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(path);
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.problems.size(), 1u);
  const std::string text = r.problems[0].text();
  EXPECT_EQ(r.problems[0].field, "render.views[1]");
  EXPECT_EQ(text.rfind(path + ":7:19: render.views[1]: unknown view 'dept': expected shaded, stress, depth, "
                              "segmentation or normals (did you mean 'depth'?)",
                       0),
            0u)
      << text;
}

TEST(SceneViews, SegmentationIdsMustFitEightBits) {
  std::string instruments = "instruments:\n";
  for (int k = 0; k < render::kMaxInstrumentsWithIds + 1; ++k)
    instruments += "  - {type: probe, script: [{t: 0, tip: [0, 0, " + std::to_string(0.2 + 0.01 * k) + "]}]}\n";
  const vdmsim::SceneLoadResult r =
      vdmsim::load_scene(views_scene("many.yaml", "render: {views: [segmentation]}\n", instruments));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.problems.back().text().find("render.views: the segmentation view's 8-bit ids name at most 254 instruments"),
            std::string::npos)
      << r.problems.back().text();
  const vdmsim::SceneLoadResult depth =
      vdmsim::load_scene(views_scene("many_depth.yaml", "render: {views: [depth]}\n", instruments));
  EXPECT_TRUE(depth.ok()) << (depth.problems.empty() ? "" : depth.problems.back().text());
}

TEST(SceneViews, CheckExitsWith2OnAnUnknownViewAndVideoNeedsAPictureView) {
  const std::string bad = views_scene("cli_unknown.yaml", "render:\n  views: [segmentaton]\n");
  const vdmsim::test::CliResult r = vdmsim::test::run_cli(VDMSIM_BINARY, "check " + bad);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(bad + ":7:11: render.views[0]: unknown view 'segmentaton'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("did you mean 'segmentation'?"), std::string::npos) << r.output;

  const fs::path out = vdmsim::test::scratch_dir("scene_views") / "video_out";
  const std::string depth = views_scene("cli_depth.yaml", "render: {width: 64, height: 48, views: [depth]}\n");
  const vdmsim::test::CliResult v =
      vdmsim::test::run_cli(VDMSIM_BINARY, "run " + depth + " --video --out " + out.string());
  EXPECT_EQ(v.code, 2) << v.output;
  EXPECT_NE(v.output.find("--video needs a picture view"), std::string::npos) << v.output;
  EXPECT_FALSE(fs::exists(out / "metrics.csv"));
}
