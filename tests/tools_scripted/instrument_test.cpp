#include <gtest/gtest.h>

#include <cmath>

#include "tools_scripted/instrument.hpp"

namespace tools {
namespace {

InstrumentDef two_keys() {
  InstrumentDef d;
  d.radius = 0.005;
  d.length = 0.2;
  Keyframe a, b;
  a.t = 1.0;
  a.tip = vdm::Vec3(0, 0, 0.1);
  a.axis = vdm::Vec3(0, 0, -1);
  b.t = 3.0;
  b.tip = vdm::Vec3(0.2, 0, 0.1);
  b.axis = vdm::Vec3(1, 0, 0);
  d.script = {a, b};
  return d;
}

TEST(Instrument, WaitsBeforeTheFirstKeyAndStaysAfterTheLast) {
  const InstrumentDef d = two_keys();
  EXPECT_EQ(pose_at(d, 0.0).tip, vdm::Vec3(0, 0, 0.1));
  EXPECT_EQ(pose_at(d, 9.0).tip, vdm::Vec3(0.2, 0, 0.1));
}

TEST(Instrument, LinearPositionAndSlerpedAxis) {
  const InstrumentPose p = pose_at(two_keys(), 2.0);
  EXPECT_LT((p.tip - vdm::Vec3(0.1, 0, 0.1)).norm(), 1e-15);
  EXPECT_NEAR(p.axis.norm(), 1.0, 1e-12);
  EXPECT_LT((p.axis - vdm::Vec3(1, 0, -1).normalized()).norm(), 1e-12);  // halfway round
}

TEST(Instrument, MissingFieldsCarryOver) {
  InstrumentDef d = two_keys();
  Keyframe c;
  c.t = 4.0;
  c.jaw_closed = true;
  d.script.push_back(c);
  const InstrumentPose p = pose_at(d, 4.0);
  EXPECT_EQ(p.tip, vdm::Vec3(0.2, 0, 0.1));
  EXPECT_TRUE(p.jaw_closed);
}

TEST(Instrument, ProbeCapsuleEndsAtTheTip) {
  const InstrumentDef d = two_keys();
  const vdm::Capsule c = probe_capsule(d, pose_at(d, 0.0));
  vdm::Vec3 p, n;
  EXPECT_NEAR(vdm::capsule_distance(c, vdm::Vec3(0, 0, 0.1), p, n), 0.0, 1e-15);
  EXPECT_NEAR((c.p1 - c.p0).norm() + 2 * c.radius, d.length, 1e-15);
}

}  // namespace
}  // namespace tools
