// render.camera.focus: instruments: the automatic camera frames the instruments' working area
// (their tips while in or near contact, padded), not the whole organ.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "app/run/instrument_focus.hpp"
#include "render/camera.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

PreparedScene prepare_focus_scene(const std::string& name, const std::string& render) {
  const std::filesystem::path p = test::scratch_dir("instrument_focus") / (name + ".yaml");
  std::ofstream(p) << "organ:\n  mesh: " << VDMSIM_SOURCE_DIR << "/assets/meshes/liver_L4.obj\n"
                   << "  material: {bulk_modulus: 20000, connectivity_modulus: 2000}\n"
                   << "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\n"
                   << "simulation: {frames: 30, dt: 0.05, effects: [contact]}\n"
                   << "instruments:\n  - type: probe\n    radius: 0.004\n    script:\n"
                   << "      - {t: 0, tip: [0.035, 0, 0.3]}\n"  // far above: not working yet
                   << "      - {t: 0.5, on_surface: {from: [0.035, 0, 0.3], toward: [0, 0, -1]}, depth: -0.005}\n"
                   << "      - {t: 1, on_surface: {from: [0.035, 0, 0.3], toward: [0, 0, -1]}, depth: 0.012}\n"
                   << "render:\n" << render;
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  return ps;
}

TEST(InstrumentFocus, TheWorkingAreaIsAroundTheDentNotTheOrganOrTheApproach) {
  const PreparedScene ps = prepare_focus_scene("focus", "  camera: {focus: instruments}\n");
  ASSERT_EQ(ps.scene.render.settings.focus, render::CameraFocus::instruments);
  vdm::Vec3 lo, hi;
  ASSERT_TRUE(instruments_working_area(ps, lo, hi));
  const vdm::Vec3 surface = ps.surface_hits.at(0).point, deepest = *ps.scene.instruments[0].script[2].tip;
  // The surface point and the deepest tip are inside, with room around them for the dent.
  for (const vdm::Vec3& p : {surface, deepest}) {
    EXPECT_GT((p - lo).minCoeff(), 0.02);
    EXPECT_GT((hi - p).minCoeff(), 0.02);
  }
  // The approach from 0.3 m is not: the box is the working area, far smaller than the organ.
  EXPECT_LT(hi.z(), 0.15);
  const vdm::Vec3 organ = ps.organ().model.rest.positions.colwise().maxCoeff() - ps.organ().model.rest.positions.colwise().minCoeff();
  EXPECT_LT((hi - lo).x(), 0.5 * organ.x());
  // Its camera is nearer the dent than the organ framing's: the dent is larger in the picture.
  const render::RenderSettings framed = framed_settings(ps);
  ASSERT_TRUE(framed.has_focus_box);
  const render::Camera near = render::auto_frame(framed.focus_lo, framed.focus_hi, 40, 4.0 / 3.0);
  const render::Camera whole = render::auto_frame(ps.organ().model.rest.positions.colwise().minCoeff().transpose(),
                                                  ps.organ().model.rest.positions.colwise().maxCoeff().transpose(), 40, 4.0 / 3.0);
  EXPECT_LT((near.eye - surface).norm(), 0.5 * (whole.eye - surface).norm());
}

TEST(InstrumentFocus, TheOrganFramingStaysTheDefault) {
  const PreparedScene ps = prepare_focus_scene("default", "  width: 64\n");
  EXPECT_EQ(ps.scene.render.settings.focus, render::CameraFocus::organ);
  EXPECT_FALSE(framed_settings(ps).has_focus_box);
}

TEST(InstrumentFocus, FocusWithAnExplicitCameraIsAnError) {
  const std::filesystem::path p = test::scratch_dir("instrument_focus") / "both.yaml";
  std::ofstream(p) << "organ: {mesh: " << VDMSIM_SOURCE_DIR << "/assets/meshes/liver_L4.obj}\n"
                   << "render:\n  camera: {eye: [0, -1, 0.5], target: [0, 0, 0], focus: instruments}\n";
  const SceneLoadResult r = load_scene(p.string());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.problems[0].text().find(p.string() + ":3:"), std::string::npos) << r.problems[0].text();
  EXPECT_NE(r.problems[0].text().find("render.camera.focus: is for the automatic camera"), std::string::npos)
      << r.problems[0].text();
}

}  // namespace
}  // namespace vdmsim
