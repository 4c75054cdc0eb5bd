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

// A grasper's shaft turning about its tip: its far end moves by the angle times the length;
// told how far back from the tip it can meet anything, by the angle times that reach, and
// never by less than its jaws' (they always count).
TEST(Instrument, GraspersMotionCountsTheShaftAsFarAsItCanReach) {
  InstrumentDef g;
  g.type = InstrumentDef::Type::grasper;
  g.radius = 0.0025;
  g.length = 0.32;
  g.jaw_length = 0.016;
  InstrumentPose a, b;
  a.tip = b.tip = vdm::Vec3(0.01, 0.02, 0.03);
  a.axis = vdm::Vec3(0, 0, -1);
  const double angle = 0.1;
  b.axis = vdm::Vec3(std::sin(angle), 0, -std::cos(angle));
  a.jaw_opening = b.jaw_opening = 1;
  EXPECT_NEAR(instrument_motion(g, a, b), angle * 0.32, 1e-12);
  EXPECT_NEAR(instrument_motion(g, a, b, 0.05), angle * 0.05, 1e-12);
  EXPECT_NEAR(instrument_motion(g, a, b, 0.0), angle * (0.016 + 3 * 0.0025), 1e-12);
  EXPECT_NEAR(instrument_motion(g, a, b, 1.0), angle * 0.32, 1e-12);  // never beyond the shaft's end
}

TEST(Instrument, ProbeCapsuleEndsAtTheTip) {
  const InstrumentDef d = two_keys();
  const vdm::Capsule c = probe_capsule(d, pose_at(d, 0.0));
  vdm::Vec3 p, n;
  EXPECT_NEAR(vdm::capsule_distance(c, vdm::Vec3(0, 0, 0.1), p, n), 0.0, 1e-15);
  EXPECT_NEAR((c.p1 - c.p0).norm() + 2 * c.radius, d.length, 1e-15);
}


// A poke: down, hold, up, with a sideways drift, interpolated by the spline.
InstrumentDef poke_spline() {
  InstrumentDef d;
  d.path = InstrumentDef::Path::spline;
  const double t[] = {0.0, 0.5, 1.5, 2.0, 3.0};
  const vdm::Vec3 p[] = {{0, 0, 0.075}, {0.01, 0, 0.06}, {0.02, 0, 0.045}, {0.02, 0, 0.045}, {0.03, 0, 0.075}};
  for (int k = 0; k < 5; ++k) {
    Keyframe key;
    key.t = t[k];
    key.tip = p[k];
    if (k == 0) key.axis = vdm::Vec3(0, 0, -1);
    d.script.push_back(key);
  }
  return d;
}

TEST(InstrumentSpline, PassesThroughEveryKeyframeAndHoldsExactly) {
  const InstrumentDef d = poke_spline();
  for (const Keyframe& k : d.script) EXPECT_NEAR((pose_at(d, k.t).tip - *k.tip).norm(), 0.0, 1e-15) << k.t;
  for (double t = 1.5; t <= 2.0; t += 0.05) EXPECT_NEAR((pose_at(d, t).tip - vdm::Vec3(0.02, 0, 0.045)).norm(), 0.0, 1e-15);
}

TEST(InstrumentSpline, VelocityIsContinuousAndTheSplineNeverOvershoots) {
  const InstrumentDef d = poke_spline();
  const double e = 1e-6;
  for (const Keyframe& k : d.script) {
    const vdm::Vec3 left = (pose_at(d, k.t).tip - pose_at(d, k.t - e).tip) / e;
    const vdm::Vec3 right = (pose_at(d, k.t + e).tip - pose_at(d, k.t).tip) / e;
    EXPECT_LT((left - right).norm(), 1e-4) << "velocity jumps at t = " << k.t;
  }
  // The linear path's velocity jumps at the same keyframe (so the check above can fail).
  InstrumentDef lin = d;
  lin.path = InstrumentDef::Path::linear;
  const vdm::Vec3 jl = (pose_at(lin, 0.5).tip - pose_at(lin, 0.5 - e).tip) / e;
  const vdm::Vec3 jr = (pose_at(lin, 0.5 + e).tip - pose_at(lin, 0.5).tip) / e;
  EXPECT_GT((jl - jr).norm(), 1e-3);
  // Between two keyframes every coordinate stays within their values (no overshoot), and the
  // instrument starts and ends at rest.
  for (size_t k = 0; k + 1 < d.script.size(); ++k)
    for (int i = 1; i < 100; ++i) {
      const double t = d.script[k].t + (d.script[k + 1].t - d.script[k].t) * i / 100.0;
      const vdm::Vec3 p = pose_at(d, t).tip;
      for (int c = 0; c < 3; ++c) {
        EXPECT_GE(p[c], std::min((*d.script[k].tip)[c], (*d.script[k + 1].tip)[c]) - 1e-15);
        EXPECT_LE(p[c], std::max((*d.script[k].tip)[c], (*d.script[k + 1].tip)[c]) + 1e-15);
      }
    }
  EXPECT_LT((pose_at(d, e).tip - pose_at(d, 0).tip).norm() / e, 1e-4);
  EXPECT_LT((pose_at(d, 3.0).tip - pose_at(d, 3.0 - e).tip).norm() / e, 1e-4);
}

}  // namespace
}  // namespace tools
