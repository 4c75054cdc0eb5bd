// The geometric pass of `vdmsim check` (issue 29): the times it samples, and when a probe
// pressed 10 mm into the project's liver first touches it and how deep it goes, on a 10k-node
// organ over 200 frames in well under a second.
#include <gtest/gtest.h>

#include <chrono>

#include "app/check/instrument_reach.hpp"
#include "app/mesh_prep/ray_locate.hpp"
#include "app/scene/organ_generator.hpp"

namespace {

using vdmsim::InstrumentDef;
using vdmsim::Keyframe;

// A probe going from 10 mm outside the surface point below (x, y) along its normal to `depth`
// inside at t = 1, and back out at t = 2.
InstrumentDef press(const vdm::SurfaceMesh& organ, double x, double y, double depth) {
  const vdmsim::RayHit hit = vdmsim::first_hit(organ, vdm::Vec3(x, y, 0.3), vdm::Vec3(0, 0, -1));
  EXPECT_TRUE(hit.hit);
  InstrumentDef def;
  Keyframe a, b, c;
  a.t = 0, b.t = 1, c.t = 2;
  a.tip = c.tip = vdm::Vec3(hit.point + 0.01 * hit.normal);
  b.tip = vdm::Vec3(hit.point - depth * hit.normal);
  a.axis = vdm::Vec3(-hit.normal);
  def.script = {a, b, c};
  return def;
}

TEST(InstrumentReach, SamplesEveryFrameAndTheKeyframesWithinTheFrames) {
  InstrumentDef def;
  Keyframe a, b, c;
  a.t = 0, b.t = 0.25, c.t = 3;
  a.tip = vdm::Vec3::Zero();
  def.script = {a, b, c};
  const std::vector<double> t = vdmsim::reach_times(def, 10, 0.1);
  // Frames 0 .. 9 at 0, 0.1 .. 0.9 and the keyframe 0.25; not 3 (after the last frame)
  ASSERT_EQ(t.size(), 11u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 0.9);
  EXPECT_DOUBLE_EQ(t[3], 0.25);
  EXPECT_LE(vdmsim::reach_times(def, 10000000, 1e-3).size(), size_t(vdmsim::kMaxSampledFrames) + 3);
}

TEST(InstrumentReach, AProbePressed10MmTouchesHalfWayAndGoes10MmDeep) {
  const vdm::SurfaceMesh organ = vdmsim::make_liver_mesh(5);  // 10242 nodes
  const InstrumentDef def = press(organ, 0.05, 0, 0.01);
  const std::vector<double> times = vdmsim::reach_times(def, 201, 0.01);  // 201 frames: t = 0 to 2
  const auto t0 = std::chrono::steady_clock::now();
  const vdmsim::InstrumentReach r = vdmsim::instrument_reach(def, organ, times);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("10242 nodes, %zu times: %.3f s\n", times.size(), seconds);  // (speed: a bench's job, not a test's)
  ASSERT_TRUE(r.touches);
  EXPECT_NEAR(r.start_distance, 0.01, 0.002);  // 10 mm away at the start
  EXPECT_EQ(r.start_depth, 0.0);
  EXPECT_NEAR(r.first_touch, 0.5, 0.08);        // half way down (node spacing ~3 mm)
  EXPECT_NEAR(r.deepest, 0.01, 0.0005);
  EXPECT_NEAR(r.deepest_at, 1.0, 1e-12);
}

TEST(InstrumentReach, AProbeFarAwayNeverTouchesAndSaysHowFar) {
  const vdm::SurfaceMesh organ = vdmsim::make_liver_mesh(3);
  InstrumentDef def;
  Keyframe a;
  a.tip = vdm::Vec3(220, 0, 0);  // millimetres read as metres
  def.script = {a};
  const vdmsim::InstrumentReach r = vdmsim::instrument_reach(def, organ, vdmsim::reach_times(def, 10, 0.1));
  EXPECT_FALSE(r.touches);
  EXPECT_GT(r.closest, 219.0);
  EXPECT_LT(r.closest, 220.0);
}

TEST(InstrumentReach, AGrasperStartingInsideIsInsideAtTimeZero) {
  const vdm::SurfaceMesh organ = vdmsim::make_liver_mesh(3);
  InstrumentDef def;
  def.type = InstrumentDef::Type::grasper;
  Keyframe a;
  a.tip = vdm::Vec3(0, 0, 0.01);  // the liver's centre
  def.script = {a};
  const vdmsim::InstrumentReach r = vdmsim::instrument_reach(def, organ, vdmsim::reach_times(def, 5, 0.1));
  EXPECT_LT(r.start_distance, 0.0);
  EXPECT_GT(r.start_depth, 0.01);
  EXPECT_TRUE(r.touches);
  EXPECT_EQ(r.first_touch, 0.0);
}

}  // namespace
