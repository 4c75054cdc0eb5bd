// The laparoscopic keys: render.camera's endoscope (port, look_at, depth, angle, roll, field of
// view, script) and instruments through ports (instruments[].port with tips or port
// coordinates, roll). What they describe is read as given; what cannot be (a framing key on an
// endoscope, an endoscope key on a framing camera, a keyframe whose shaft cannot pass its port)
// is an error at its file:line:col.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/scene/scene.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "support/scratch_dir.hpp"
#include "tools_scripted/instrument.hpp"

namespace {

namespace fs = std::filesystem;

std::string ports_scene(const std::string& name, const std::string& render, const std::string& instruments = "") {
  const fs::path p = vdmsim::test::scratch_dir("scene_ports") / name;
  std::ofstream(p) << "name: ports\norgan:\n  mesh: " << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "\n  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\nsimulation: {frames: 2, dt: 0.04}\n"
                   << instruments << render;
  return p.string();
}

// The problem whose field is `field`, or the empty text.
std::string problem_at(const vdmsim::SceneLoadResult& r, const std::string& field) {
  for (const auto& p : r.problems)
    if (p.field == field) return p.text();
  return "";
}

const char* const kScope =
    "render:\n  camera:\n    type: endoscope\n    port: [0, -0.15, 0.12]\n    look_at: [0, 0, 0.02]\n"
    "    depth: 0.06\n    angle_deg: 30\n    roll_deg: 180\n    fov_deg: 80\n"
    "    script:\n      - {t: 0.5, look_at: [0.02, 0, 0.02]}\n      - {t: 1.0, depth: 0.08, roll_deg: 150}\n";

}  // namespace

TEST(ScenePorts, AnEndoscopeIsReadAsGiven) {
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(ports_scene("scope.yaml", kScope));
  ASSERT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0].text());
  const render::RenderSettings& rs = r.scene.render.settings;
  EXPECT_EQ(rs.camera_type, render::CameraType::endoscope);
  EXPECT_FALSE(rs.auto_camera);
  EXPECT_FALSE(rs.floor);  // the abdomen's wall instead
  const tools::EndoscopeDef& e = rs.endoscope;
  EXPECT_EQ(e.port, vdm::Vec3(0, -0.15, 0.12));
  EXPECT_EQ(e.look_at, vdm::Vec3(0, 0, 0.02));
  EXPECT_EQ(e.depth, 0.06);
  EXPECT_EQ(e.angle_deg, 30);
  EXPECT_EQ(e.roll_deg, 180);
  EXPECT_EQ(e.fov_deg, 80);
  ASSERT_EQ(e.script.size(), 2u);
  EXPECT_EQ(e.script[0].t, 0.5);
  EXPECT_EQ(*e.script[0].look_at, vdm::Vec3(0.02, 0, 0.02));
  EXPECT_FALSE(e.script[0].depth);
  EXPECT_EQ(*e.script[1].depth, 0.08);
  EXPECT_EQ(*e.script[1].roll_deg, 150);
  // Defaults: a straight scope of 70 degrees, 5 cm in.
  const vdmsim::SceneLoadResult plain = vdmsim::load_scene(
      ports_scene("plain.yaml", "render:\n  camera: {type: endoscope, port: [0, -0.15, 0.12], look_at: [0, 0, 0]}\n"));
  ASSERT_TRUE(plain.ok()) << (plain.problems.empty() ? "" : plain.problems[0].text());
  EXPECT_EQ(plain.scene.render.settings.endoscope.fov_deg, 70);
  EXPECT_EQ(plain.scene.render.settings.endoscope.angle_deg, 0);
  EXPECT_EQ(plain.scene.render.settings.endoscope.depth, 0.05);
}

TEST(ScenePorts, WhatAnEndoscopeCannotBeIsAnErrorAtItsPlace) {
  const std::string framing_key = ports_scene(
      "eye.yaml", "render:\n  camera: {type: endoscope, port: [0, -0.15, 0.12], look_at: [0, 0, 0], eye: [0, -1, 1]}\n");
  const vdmsim::SceneLoadResult a = vdmsim::load_scene(framing_key);
  EXPECT_EQ(problem_at(a, "render.camera.eye").rfind(framing_key + ":7:", 0), 0u) << problem_at(a, "render.camera.eye");
  EXPECT_NE(problem_at(a, "render.camera.eye").find("is for the framing camera"), std::string::npos);

  const std::string no_type = ports_scene("no_type.yaml", "render:\n  camera: {port: [0, -0.15, 0.12], look_at: [0, 0, 0]}\n");
  const vdmsim::SceneLoadResult b = vdmsim::load_scene(no_type);
  EXPECT_NE(problem_at(b, "render.camera.port").find("add type: endoscope"), std::string::npos);
  EXPECT_NE(problem_at(b, "render.camera.look_at").find("add type: endoscope"), std::string::npos);

  const std::string at_port =
      ports_scene("at_port.yaml", "render:\n  camera: {type: endoscope, port: [0, -0.15, 0.12], look_at: [0, -0.15, 0.12]}\n");
  EXPECT_NE(problem_at(vdmsim::load_scene(at_port), "render.camera.look_at").find("aimed at its own port"), std::string::npos);

  const std::string missing = ports_scene("missing.yaml", "render:\n  camera: {type: endoscope, look_at: [0, 0, 0]}\n");
  EXPECT_NE(problem_at(vdmsim::load_scene(missing), "render.camera.port").find("missing required field 'port'"),
            std::string::npos);

  // A keyframe at or before the one before it, one aimed at the port, a bad type.
  const std::string script = ports_scene(
      "script.yaml",
      "render:\n  camera:\n    type: endoscope\n    port: [0, -0.15, 0.12]\n    look_at: [0, 0, 0]\n    script:\n"
      "      - {t: 1.0, depth: 0.07}\n      - {t: 1.0, look_at: [0, -0.15, 0.12]}\n");
  const vdmsim::SceneLoadResult c = vdmsim::load_scene(script);
  const std::string t_text = problem_at(c, "render.camera.script[1].t");
  EXPECT_EQ(t_text.rfind(script + ":13:13:", 0), 0u) << t_text;
  EXPECT_NE(t_text.find("must increase"), std::string::npos);
  EXPECT_NE(problem_at(c, "render.camera.script[1].look_at").find("aimed at its own port"), std::string::npos);
  const std::string type = ports_scene("type.yaml", "render:\n  camera: {type: endoscop, port: [0, 0, 1], look_at: [0, 0, 0]}\n");
  EXPECT_NE(problem_at(vdmsim::load_scene(type), "render.camera.type").find("did you mean 'endoscope'"), std::string::npos);
}

TEST(ScenePorts, APortedInstrumentsShaftPassesItsPortAtEveryTime) {
  const std::string path = ports_scene(
      "ported.yaml", "",
      "instruments:\n  - type: grasper\n    port: [-0.15, -0.1, 0.12]\n    script:\n"
      "      - {t: 0.0, tip: [-0.1, -0.03, 0.06], jaw: open}\n"
      "      - {t: 0.5, pan_deg: 40, tilt_deg: 30, depth: 0.1, roll_deg: 90}\n"
      "      - {t: 0.7, jaw: closed}\n"
      "      - {t: 1.0, depth: 0.12}\n");
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(path);
  ASSERT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0].text());
  const tools::InstrumentDef& in = r.scene.instruments[0];
  ASSERT_TRUE(in.port);
  const vdm::Vec3 port = *in.port;
  // Port coordinates: 40 degrees from +x toward +y, 30 below the horizontal, 10 cm in.
  const double k = M_PI / 180;
  const vdm::Vec3 d1(std::cos(30 * k) * std::cos(40 * k), std::cos(30 * k) * std::sin(40 * k), -std::sin(30 * k));
  EXPECT_LT((*in.script[1].tip - (port + 0.1 * d1)).norm(), 1e-15);
  // The fourth keeps the pan and tilt (past a keyframe that moves only the jaws) and goes 12 cm in.
  EXPECT_FALSE(in.script[2].tip);
  EXPECT_LT((*in.script[3].tip - (port + 0.12 * d1)).norm(), 1e-15);
  for (double t = 0; t <= 1.2; t += 0.05) {
    const tools::InstrumentPose pose = tools::pose_at(in, t);
    // The axis runs from the port through the tip: the port is on the shaft's line.
    const vdm::Vec3 to_port = port - pose.tip;
    EXPECT_LT((to_port - to_port.dot(pose.axis) * pose.axis).norm(), 1e-12) << t;
    EXPECT_LT(to_port.dot(pose.axis), 0) << t;  // behind the tip, toward the handle
    EXPECT_NEAR(pose.axis.norm(), 1, 1e-12);
  }
  // The roll turns the instrument frame about the shaft, linearly between keyframes.
  EXPECT_DOUBLE_EQ(tools::pose_at(in, 0.25).roll_deg, 45);
  const tools::InstrumentPose rolled = tools::pose_at(in, 0.5);
  tools::InstrumentPose unrolled = rolled;
  unrolled.roll_deg = 0;
  const Eigen::Matrix3d a = tools::instrument_frame(unrolled).linear(), b = tools::instrument_frame(rolled).linear();
  EXPECT_LT((b.col(2) - a.col(2)).norm(), 1e-12);
  EXPECT_LT((b.col(0) - a.col(1)).norm(), 1e-12);  // x to y: a right-handed quarter turn about z
}

TEST(ScenePorts, AKeyframeWhoseShaftCannotPassItsPortIsRefused) {
  // An axis with a port, port coordinates without one, a tip at the port, out of reach, and
  // port coordinates with nothing to keep the missing ones from.
  const std::string path = ports_scene(
      "bad.yaml", "",
      "instruments:\n  - type: probe\n    port: [0, -0.15, 0.12]\n    length: 0.2\n    script:\n"
      "      - {t: 0.0, tip: [0, 0, 0.07], axis: [0, 0, -1]}\n"
      "      - {t: 0.5, tip: [0, -0.15, 0.12]}\n"
      "      - {t: 1.0, tip: [0, 0.2, 0.0]}\n"
      "  - type: probe\n    script:\n      - {t: 0.0, tip: [0, 0, 0.07], pan_deg: 10}\n"
      "  - type: probe\n    port: [0, -0.15, 0.12]\n    script:\n      - {t: 0.0, pan_deg: 10}\n");
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(path);
  ASSERT_FALSE(r.ok());
  const std::string axis = problem_at(r, "instruments[0].script[0].axis");
  EXPECT_EQ(axis.rfind(path + ":11:43:", 0), 0u) << axis;
  EXPECT_NE(axis.find("runs from the port through the tip"), std::string::npos);
  EXPECT_NE(problem_at(r, "instruments[0].script[1].tip").find("at the port"), std::string::npos);
  EXPECT_NE(problem_at(r, "instruments[0].script[2]").find("farther than the instrument is long"), std::string::npos);
  EXPECT_NE(problem_at(r, "instruments[1].script[0].pan_deg").find("need the instrument's port"), std::string::npos);
  EXPECT_NE(problem_at(r, "instruments[2].script[0]").find("gives pan_deg, tilt_deg and depth"), std::string::npos);

  // A tip behind the port, on its side away from the organ: refused once the organ is placed,
  // at the keyframe.
  const std::string behind = ports_scene(
      "behind.yaml", "",
      "instruments:\n  - type: probe\n    port: [0, -0.15, 0.12]\n    script:\n"
      "      - {t: 0.0, tip: [0, -0.1, 0.09]}\n      - {t: 0.5, tip: [0, -0.2, 0.15]}\n");
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_FALSE(vdmsim::prepare_scene(behind, ps, problems));
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems.back().field, "instruments[0].script[1]");
  EXPECT_EQ(problems.back().text().rfind(behind + ":11:", 0), 0u) << problems.back().text();
  EXPECT_NE(problems.back().text().find("behind the port"), std::string::npos);
}

TEST(ScenePorts, AGraspersJawLookIsReadAndAnUnknownOneRefused) {
  const std::string good = ports_scene(
      "jaws.yaml", "", "instruments:\n  - type: grasper\n    jaws: maryland\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(good);
  ASSERT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0].text());
  EXPECT_EQ(r.scene.instruments[0].jaw_look, tools::InstrumentDef::JawLook::maryland);
  const std::string bad = ports_scene(
      "bad_jaws.yaml", "", "instruments:\n  - type: grasper\n    jaws: fenestratd\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const std::string text = problem_at(vdmsim::load_scene(bad), "instruments[0].jaws");
  EXPECT_EQ(text.rfind(bad + ":8:11:", 0), 0u) << text;
  EXPECT_NE(text.find("did you mean 'fenestrated'"), std::string::npos) << text;
}

TEST(ScenePorts, AProbesHookLookIsReadAndWarnedWhereItCannotBeDrawn) {
  const std::string good = ports_scene(
      "hook.yaml", "", "instruments:\n  - type: probe\n    look: hook\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const vdmsim::SceneLoadResult r = vdmsim::load_scene(good);
  ASSERT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems[0].text());
  EXPECT_TRUE(r.problems.empty()) << r.problems[0].text();
  EXPECT_EQ(r.scene.instruments[0].probe_look, tools::InstrumentDef::ProbeLook::hook);
  // On a grasper, or on a probe whose shape is not a capsule, the look is warned about (the
  // scene still loads; such an instrument is drawn as it collides).
  const std::string grasper = ports_scene(
      "hook_grasper.yaml", "", "instruments:\n  - type: grasper\n    look: hook\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const vdmsim::SceneLoadResult g = vdmsim::load_scene(grasper);
  EXPECT_TRUE(g.ok());
  EXPECT_NE(problem_at(g, "instruments[0].look").find("a grasper's look is its jaws"), std::string::npos);
  const std::string box = ports_scene("hook_box.yaml", "",
                                      "instruments:\n  - type: probe\n    shape: {type: box, size: [0.01, 0.01, 0.02]}\n"
                                      "    look: hook\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const vdmsim::SceneLoadResult b = vdmsim::load_scene(box);
  EXPECT_TRUE(b.ok());
  EXPECT_NE(problem_at(b, "instruments[0].look").find("capsule probe only"), std::string::npos);
  const std::string bad = ports_scene(
      "bad_hook.yaml", "", "instruments:\n  - type: probe\n    look: hok\n    script: [{t: 0, tip: [0, 0, 0.08]}]\n");
  const std::string text = problem_at(vdmsim::load_scene(bad), "instruments[0].look");
  EXPECT_EQ(text.rfind(bad + ":8:11:", 0), 0u) << text;
  EXPECT_NE(text.find("did you mean 'hook'"), std::string::npos) << text;
}
