// Keyframes placed on the organ (instruments[].script[].on_surface): the ray is cast against
// the organ as placed, the tip goes `depth` along the inward normal, `align` turns the axis
// along it, and a ray that misses (or starts inside) is an error naming its line and column.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/check/instrument_reach.hpp"
#include "app/cli/commands.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "app/simulation/tool_depth.hpp"
#include "engine/shapes.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

// A 10 cm cube (a node every 10 mm along its faces' grid lines) and a 5 cm sphere, written as
// OBJ files the scenes name.
fs::path mesh_file(const std::string& name) {
  const fs::path dir = test::scratch_dir("surface_keyframes");
  const fs::path p = dir / (name + ".obj");
  if (!fs::exists(p)) {
    const vdm::SurfaceMesh m = name == "cube" ? vdm::make_box(vdm::Vec3(0.1, 0.1, 0.1), 10, 10, 10) : vdm::make_icosphere(0.05, 4);
    std::string error;
    EXPECT_TRUE(save_obj(m, p.string(), "", error)) << error;
  }
  return p;
}

// The organ's bottom (below `fixed_top`) is held.
fs::path scene_file(const std::string& name, const std::string& mesh, const std::string& organ_extra,
                    const std::string& script, double fixed_top = -0.04) {
  const fs::path p = test::scratch_dir("surface_keyframes") / (name + ".yaml");
  std::ofstream(p) << "organ:\n  mesh: " << mesh_file(mesh).string() << "\n" << organ_extra
                   << "  material: {bulk_modulus: 20000, connectivity_modulus: 2000}\n"
                   << "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, " << fixed_top << "]}}]\n"
                   << "simulation: {frames: 10, dt: 0.1, effects: [contact]}\n"
                   << "instruments:\n  - type: probe\n    radius: 0.003\n    script:\n"
                   << script;
  return p;
}

TEST(SurfaceKeyframes, ATipPlacedFiveMillimetresDeepIsFiveMillimetresInsideThePlacedCube) {
  // The cube moved up by 0.3 m: its top face is at z = 0.35, where the ray from above meets it.
  const fs::path p = scene_file("cube_depth", "cube", "  translate: [0, 0, 0.3]\n",
                                "      - {t: 0, on_surface: {from: [0.01, 0.02, 1], toward: [0, 0, -2]}, depth: -0.01}\n"
                                "      - {t: 1, on_surface: {from: [0.01, 0.02, 1], toward: [0, 0, -2]}, depth: 0.005, align: true}\n",
                                0.26);
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  ASSERT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  const auto& script = ps.scene.instruments[0].script;
  ASSERT_EQ(ps.surface_hits.size(), 2u);
  EXPECT_NEAR((ps.surface_hits[0].point - vdm::Vec3(0.01, 0.02, 0.35)).norm(), 0, 1e-12);
  EXPECT_NEAR((ps.surface_hits[0].normal - vdm::Vec3::UnitZ()).norm(), 0, 1e-12);
  EXPECT_NEAR((*script[0].tip - vdm::Vec3(0.01, 0.02, 0.36)).norm(), 0, 1e-12);  // 10 mm above
  EXPECT_NEAR((*script[1].tip - vdm::Vec3(0.01, 0.02, 0.345)).norm(), 0, 1e-12);
  EXPECT_NEAR((*script[1].axis - vdm::Vec3(0, 0, -1)).norm(), 0, 1e-12);  // aligned: pushing straight in
  EXPECT_FALSE(script[0].axis.has_value());  // not aligned: the default axis
  // Measured independently: the tip's depth inside the placed rest surface, and check's pass.
  const vdm::SurfaceMesh& rest = ps.organ().model.rest;
  EXPECT_NEAR(depth_inside(rest.positions, rest.triangles, *script[1].tip), 0.005, 1e-12);
  EXPECT_EQ(depth_inside(rest.positions, rest.triangles, *script[0].tip), 0.0);
  // 11 frames of 0.1 s: t = 0 to 1 s, the whole script.
  const InstrumentReach reach = instrument_reach(ps.scene.instruments[0], rest, reach_times(ps.scene.instruments[0], 11, 0.1));
  EXPECT_NEAR(reach.deepest, 0.005, 1e-12);
  EXPECT_NEAR(reach.deepest_at, 1.0, 1e-12);
  EXPECT_NEAR(reach.start_distance, 0.01, 1e-12);  // the capsule's end 10 mm above the node under it
}

TEST(SurfaceKeyframes, OnARotatedSphereTheTipGoesAlongTheInwardNormal) {
  // An oblique ray onto the sphere turned and moved: the tip is 5 mm from the hit facet's plane
  // along its normal, and about 5 mm inside the sphere (the facets meet at a few degrees).
  const vdm::Vec3 c(0.1, -0.2, 0.3);
  const fs::path p = scene_file("sphere_depth", "sphere", "  rotate_deg: [30, 0, 60]\n  translate: [0.1, -0.2, 0.3]\n",
                                "      - {t: 0, on_surface: {from: [0.3, 0, 0.5], toward: [-0.2, -0.2, -0.2]}, depth: 0.005, align: true}\n",
                                0.26);
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  ASSERT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  const SurfaceHit& h = ps.surface_hits.at(0);
  const Keyframe& key = ps.scene.instruments[0].script[0];
  EXPECT_NEAR((h.point - c).norm(), 0.05, 0.05 * 0.005);  // on the sphere, within a facet's sag
  EXPECT_GT(h.normal.dot((h.point - c).normalized()), 0.995);
  EXPECT_NEAR((*key.tip - (h.point - 0.005 * h.normal)).norm(), 0, 1e-15);
  EXPECT_NEAR((*key.axis + h.normal).norm(), 0, 1e-15);
  const double depth = depth_inside(ps.organ().model.rest.positions, ps.organ().model.rest.triangles, *key.tip);
  EXPECT_LE(depth, 0.005 + 1e-12);
  EXPECT_GT(depth, 0.005 * 0.99);
}

TEST(SurfaceKeyframes, ARayThatMissesTheOrganIsAnErrorAtItsLineAndColumn) {
  const fs::path p = scene_file("miss", "cube", "",
                                "      - {t: 0, tip: [0, 0, 0.2]}\n"
                                "      - {t: 1, on_surface: {from: [0.3, 0, 1], toward: [0, 0, -1]}, depth: 0.005}\n");
  std::ostringstream out, err;
  EXPECT_EQ(cmd_check(p.string(), out, err), 2);
  EXPECT_NE(err.str().find(p.string() + ":11:28: instruments[0].script[1].on_surface: the ray from (0.3, 0, 1) toward (0, 0, -1) misses the organ"),
            std::string::npos)
      << err.str();
}

TEST(SurfaceKeyframes, ARayFromFarBeyondDoublePrecisionIsAMissNotANaN) {
  // The ray's products overflow: no tip made of NaNs, a miss.
  const fs::path p = scene_file("far", "cube", "",
                                "      - {t: 0, on_surface: {from: [1e300, 1e300, 1e300], toward: [-1, -1, -1]}}\n");
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_FALSE(prepare_scene(p.string(), ps, problems));
  ASSERT_FALSE(problems.empty());
  EXPECT_NE(problems.back().text().find("misses the organ"), std::string::npos) << problems.back().text();
}

TEST(SurfaceKeyframes, ARayFromInsideTheOrganIsAnError) {
  const fs::path p = scene_file("inside", "cube", "",
                                "      - {t: 0, on_surface: {from: [0, 0, 0], toward: [0, 0, -1]}}\n");
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_FALSE(prepare_scene(p.string(), ps, problems));
  ASSERT_FALSE(problems.empty());
  EXPECT_NE(problems.back().text().find("starts inside the organ"), std::string::npos) << problems.back().text();
}

TEST(SurfaceKeyframes, ConflictingOrMissingKeysAreNamed) {
  struct Case {
    const char* script;
    const char* expected;
  };
  const Case cases[] = {
      {"      - {t: 0, tip: [0, 0, 0.2], depth: 0.01}\n", "instruments[0].script[0].depth: depth places the tip relative to the surface"},
      {"      - {t: 0, tip: [0, 0, 0.2], on_surface: {from: [0, 0, 1], toward: [0, 0, -1]}}\n",
       "instruments[0].script[0].tip: give tip or on_surface, not both"},
      {"      - {t: 0, axis: [0, 0, -1], align: true, on_surface: {from: [0, 0, 1], toward: [0, 0, -1]}}\n",
       "instruments[0].script[0].align: give axis or align, not both"},
      {"      - {t: 0, on_surface: {from: [0, 0, 1]}}\n", "instruments[0].script[0].on_surface.toward: missing required field"},
      {"      - {t: 0, on_surface: {from: [0, 0, 1], toward: [0, 0, 0]}}\n", "the direction must not be zero"},
      {"      - {t: 0, on_surface: {from: [0, 0, 1], towards: [0, 0, -1]}}\n", "did you mean 'toward'"},
  };
  int i = 0;
  for (const Case& c : cases) {
    const fs::path p = scene_file("keys_" + std::to_string(i++), "cube", "", c.script);
    const SceneLoadResult r = load_scene(p.string());
    std::string all;
    for (const SceneProblem& q : r.problems) all += q.text() + "\n";
    EXPECT_FALSE(r.ok()) << c.script;
    EXPECT_NE(all.find(c.expected), std::string::npos) << c.script << all;
  }
}

TEST(SurfaceKeyframes, CheckPrintsWhereTheTipWasPlaced) {
  const fs::path p = scene_file("check", "cube", "",
                                "      - {t: 0, on_surface: {from: [0.01, 0.02, 1], toward: [0, 0, -1]}, depth: -0.01, align: true}\n"
                                "      - {t: 1, on_surface: {from: [0.01, 0.02, 1], toward: [0, 0, -1]}, depth: 0.005}\n");
  std::ostringstream out, err;
  ASSERT_EQ(cmd_check(p.string(), out, err), 0) << err.str();
  EXPECT_NE(out.str().find("script[0] (t = 0 s): tip 0.01 0.02 0.06 m, 10 mm outside the surface point 0.01 0.02 0.05 "
                           "(outward normal 0 0 1), axis along the inward normal"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("script[1] (t = 1 s): tip 0.01 0.02 0.045 m, 5 mm inside the surface point 0.01 0.02 0.05"),
            std::string::npos)
      << out.str();
}

}  // namespace
}  // namespace vdmsim
