// Issue 29, `vdmsim check`'s sanity report through the real binary: the user's cases (a fixed
// box in millimetres fixing the whole organ, a first keyframe in millimetres, a probe starting
// inside, 20 frames for a 1.3 s script, no material, a key the model ignores) each warned, or
// refused, naming the file and the field; and the report's numbers on a probe pressed 10 mm
// into the project's liver.
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

fs::path dir() { return vdmsim::test::scratch_dir("check_report_cli"); }

std::string write(const std::string& name, const std::string& text) {
  const fs::path p = dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

std::string liver() { return (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string(); }

vdmsim::test::CliResult check(const std::string& scene) { return vdmsim::test::run_cli(VDMSIM_BINARY, "check " + scene); }

const std::string kMaterial = "  material: {young_modulus: 3000, poisson_ratio: 0.45}\n";
const std::string kTable = "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n";

// A scene on the liver with `organ` lines after the mesh, then `rest`.
std::string scene(const std::string& name, const std::string& organ, const std::string& rest) {
  return write(name, "name: " + name + "\norgan:\n  mesh: " + liver() + "\n" + organ + rest);
}

// A probe coming down on the top of the liver (surface near z = 0.06 at x = 0.035).
// Frames 0 to 30: t = 0 to 1 s, the whole script.
const std::string kPress =
    "simulation: {frames: 31, effects: [contact]}\n"
    "instruments:\n  - type: probe\n    script:\n"
    "      - {t: 0, tip: [0.035, 0, 0.075]}\n      - {t: 1, tip: [0.035, 0, 0.05]}\n";

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CheckReportCli, ACleanSceneHasNoWarningAndAReport) {
  const std::string p = scene("clean.yaml", kMaterial + kTable, kPress);
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(has(r.output, "warning")) << r.output;
  EXPECT_TRUE(has(r.output, ": ok (2562 nodes")) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("fixed: +[0-9]+ of 2562 nodes \\([0-9.]+ %\\) on every axis"))) << r.output;
  EXPECT_TRUE(has(r.output, "organ.fixed[0]: ")) << r.output;
  EXPECT_TRUE(has(r.output, "instruments[0] (probe): first touches the organ at t = ")) << r.output;
}

TEST(CheckReportCli, AFixedBoxInMillimetresFixingEveryNodeIsAnError) {
  const std::string p =
      scene("mm_box.yaml", kMaterial + "  fixed: [{box: {min: [-300, -200, -200], max: [300, 200, 20]}}]\n", kPress);
  const auto r = check(p);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(has(r.output, p + ":")) << r.output;
  EXPECT_TRUE(has(r.output, "error: ")) << r.output;
  EXPECT_TRUE(has(r.output, "organ.fixed: all 2562 nodes are fixed on every axis: nothing can move")) << r.output;
  EXPECT_TRUE(has(r.output, "millimetres")) << r.output;
  EXPECT_FALSE(has(r.output, ": ok (")) << r.output;
}

TEST(CheckReportCli, FixingOnlyOneAxisEverywhereIsNotAnError) {
  const std::string p = scene("one_axis.yaml", kMaterial + "  fixed: [{all: true, axes: [z]}]\n", kPress);
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "fixed:      0 of 2562 nodes (0 %) on every axis, 2562 (100 %) on some axes")) << r.output;
}

TEST(CheckReportCli, AFirstKeyframeInMillimetresNeverTouches) {
  const std::string p = scene("mm_tip.yaml", kMaterial + kTable,
                              "simulation: {frames: 30, effects: [contact]}\n"
                              "instruments:\n  - type: probe\n    script:\n"
                              "      - {t: 0, tip: [220, 0, 75]}\n      - {t: 1, tip: [35, 0, 50]}\n");
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, p + ":")) << r.output;
  EXPECT_TRUE(has(r.output, "warning: instruments[0]: never touches the organ in the 30 frames")) << r.output;
  EXPECT_TRUE(has(r.output, "keyframes in millimetres?")) << r.output;
  EXPECT_TRUE(has(r.output, "instruments[0] (probe): does not touch the organ (closest ")) << r.output;
}

TEST(CheckReportCli, WithoutContactAProbeAwayFromTheOrganIsNotWarned) {
  const std::string p = scene("no_contact.yaml", kMaterial + kTable,
                              "simulation: {frames: 30, effects: [stress]}\n"
                              "instruments:\n  - type: probe\n    script:\n      - {t: 0, tip: [0.5, 0, 0.5]}\n");
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(has(r.output, "never touches")) << r.output;
  EXPECT_TRUE(has(r.output, "does not touch the organ")) << r.output;
}

TEST(CheckReportCli, AProbeStartingInsideIsWarned) {
  // A reversed axis: the probe meant to come down from above starts below the top surface.
  const std::string p = scene("inside.yaml", kMaterial + kTable,
                              "simulation: {frames: 30, effects: [contact]}\n"
                              "instruments:\n  - type: probe\n    script:\n"
                              "      - {t: 0, tip: [0.035, 0, 0.03], axis: [0, 0, 1]}\n      - {t: 1, tip: [0.035, 0, 0.05]}\n");
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "warning: instruments[0]: starts inside the organ: ")) << r.output;
  EXPECT_TRUE(has(r.output, "first touches the organ at t = 0 s")) << r.output;
}

TEST(CheckReportCli, AScriptLongerThanTheFramesSaysTheFramesNeeded) {
  // The case: 20 frames (of 1/30 s) for a 1.3 s script.
  const std::string p = scene("short.yaml", kMaterial + kTable,
                              "simulation: {frames: 20, effects: [contact]}\n"
                              "instruments:\n  - type: probe\n    script:\n"
                              "      - {t: 0, tip: [0.035, 0, 0.075]}\n      - {t: 0.6, tip: [0.035, 0, 0.05]}\n"
                              "      - {t: 1.3, tip: [0.035, 0, 0.075]}\n");
  const auto r = check(p);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "warning: simulation.frames: the script of instruments[0] runs to t = 1.3 s but 20 frames"))
      << r.output;
  // Frame f is at f / 30 s: t = 1.3 s is frame 39, so frames 0 .. 39.
  EXPECT_TRUE(has(r.output, "20 frames of 0.03333 s (the first at t = 0) end at t = 0.6333 s")) << r.output;
  EXPECT_TRUE(has(r.output, "40 frames cover it")) << r.output;
  // With those 40 frames the script is covered: no warning; with 39 it is not.
  for (const int frames : {39, 40}) {
    const std::string q = scene("covered" + std::to_string(frames) + ".yaml", kMaterial + kTable,
                                "simulation: {frames: " + std::to_string(frames) + ", effects: [contact]}\n"
                                "instruments:\n  - type: probe\n    script:\n"
                                "      - {t: 0, tip: [0.035, 0, 0.075]}\n      - {t: 0.6, tip: [0.035, 0, 0.05]}\n"
                                "      - {t: 1.3, tip: [0.035, 0, 0.075]}\n");
    const auto c = check(q);
    EXPECT_EQ(c.code, 0) << c.output;
    EXPECT_EQ(has(c.output, "warning: simulation.frames:"), frames == 39) << c.output;
  }
}

TEST(CheckReportCli, ADefaultMaterialIsWarned) {
  const auto r = check(scene("no_material.yaml", kTable, kPress));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "warning: organ.material: not given: the default material is used (young_modulus 3000 Pa, "
                                "poisson_ratio 0.45"))
      << r.output;
}

TEST(CheckReportCli, AKeyTheModelIgnoresIsWarned) {
  const auto r = check(scene("ignored.yaml",
                             "  material: {bulk_modulus: 20000, connectivity_modulus: 2000, thickness: 0.004}\n" + kTable,
                             kPress));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(has(r.output, "warning: organ.material.thickness: ignored by organ.model vdm")) << r.output;
}

// The report's numbers: a probe 10 mm outside the surface along its normal, pressed to 10 mm
// inside at t = 0.5 s and withdrawn: it touches half way down and goes 10 mm deep.
TEST(CheckReportCli, AProbePressed10MmIntoTheLiver) {
  const auto located = vdmsim::test::run_cli(VDMSIM_BINARY, "locate " + liver() + " --from 0.05 0 0.3 --toward 0 0 -1");
  ASSERT_EQ(located.code, 0) << located.output;
  double p[3], n[3];
  std::istringstream in(located.output.substr(located.output.find("point:") + 6));
  in >> p[0] >> p[1] >> p[2];
  std::istringstream in_n(located.output.substr(located.output.find("normal:") + 7));
  in_n >> n[0] >> n[1] >> n[2];
  auto tip = [&](double d) {
    std::ostringstream s;
    s.precision(9);
    s << "[" << p[0] + d * n[0] << ", " << p[1] + d * n[1] << ", " << p[2] + d * n[2] << "]";
    return s.str();
  };
  const std::string path = scene("press10.yaml", kMaterial + kTable,
                                 "simulation: {frames: 30, effects: [contact]}\n"
                                 "instruments:\n  - type: probe\n    radius: 0.004\n    script:\n"
                                 "      - {t: 0, tip: " + tip(0.01) + "}\n      - {t: 0.5, tip: " + tip(-0.01) +
                                     "}\n      - {t: 1, tip: " + tip(0.01) + "}\n");
  const auto r = check(path);
  EXPECT_EQ(r.code, 0) << r.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.output, m,
                                std::regex("first touches the organ at t = ([0-9.e-]+) s, deepest ([0-9.e-]+) mm into the "
                                           "rest surface at t = ([0-9.e-]+) s")))
      << r.output;
  EXPECT_NEAR(std::stod(m[1]), 0.25, 0.07) << r.output;  // half way down, give or take the node spacing
  EXPECT_NEAR(std::stod(m[2]), 10.0, 1.0) << r.output;
  EXPECT_NEAR(std::stod(m[3]), 0.5, 1e-6) << r.output;
}

}  // namespace
