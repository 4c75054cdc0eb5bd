#include "tools_scripted/endoscope.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using tools::EndoscopeDef;
using tools::EndoscopeKeyframe;
using tools::EndoscopePose;
using vdm::Vec3;

double degrees_between(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

// The camera's axes are a right-handed orthonormal frame.
void expect_rotation(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d r = pose.linear();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
}

TEST(Endoscope, AZeroDegreeScopeLooksAlongItsShaftFromItsTip) {
  const Vec3 port(0.02, -0.15, 0.12), look(0.0, 0.0, 0.03);
  const EndoscopePose p = tools::endoscope_pose(port, look, 0.06, 0, 0);
  expect_rotation(p.camera);
  // The tip is `depth` past the port on the line to look_at, and the camera sits there.
  EXPECT_NEAR((p.tip - port).norm(), 0.06, 1e-12);
  EXPECT_LT(((p.tip - port).normalized() - (look - port).normalized()).norm(), 1e-12);
  EXPECT_LT((p.camera.translation() - p.tip).norm(), 1e-15);
  // The optical axis (camera z) points at look_at; look_at is seen at the picture's centre.
  const Vec3 seen = p.camera.inverse() * look;
  EXPECT_GT(seen.z(), 0);
  EXPECT_NEAR(seen.x(), 0, 1e-12);
  EXPECT_NEAR(seen.y(), 0, 1e-12);
  // Roll 0: the picture's x axis is horizontal and the world's up is toward its top (-y).
  EXPECT_NEAR(p.camera.linear().col(0).z(), 0, 1e-12);
  EXPECT_LT(p.camera.linear().col(1).z(), 0);
}

TEST(Endoscope, AnAngledScopeLooksItsAngleOffTheShaftTowardThePicturesTop) {
  const Vec3 port(0, -0.15, 0.12), look(0, 0, 0.02);
  for (double angle : {30.0, 45.0}) {
    const EndoscopePose p = tools::endoscope_pose(port, look, 0.05, angle, 0);
    expect_rotation(p.camera);
    const Vec3 axis = p.camera.linear().col(2);
    EXPECT_NEAR(degrees_between(axis, p.shaft), angle, 1e-9);
    // The shaft is seen below the picture's centre (the optics look up from it): positive y.
    const Vec3 ahead = p.camera.inverse() * (p.tip + p.shaft);
    EXPECT_NEAR(ahead.x(), 0, 1e-12);
    EXPECT_GT(ahead.y(), 0);
    // Toward the top: the optical axis is higher in the world than the shaft.
    EXPECT_GT(axis.z(), p.shaft.z());
  }
}

TEST(Endoscope, RollTurnsTheAngledViewAboutTheShaftAndThePictureStaysLevel) {
  const Vec3 port(0, -0.15, 0.12), look(0, 0, 0.02);
  const EndoscopePose a = tools::endoscope_pose(port, look, 0.05, 30, 0);
  const EndoscopePose b = tools::endoscope_pose(port, look, 0.05, 30, 90);
  const EndoscopePose c = tools::endoscope_pose(port, look, 0.05, 30, 180);
  // The shaft and the tip do not move; the optical axis stays 30 degrees off the shaft.
  EXPECT_LT((a.tip - b.tip).norm(), 1e-15);
  for (const EndoscopePose* p : {&a, &b, &c}) {
    expect_rotation(p->camera);
    EXPECT_NEAR(degrees_between(p->camera.linear().col(2), p->shaft), 30, 1e-9);
    EXPECT_NEAR(p->camera.linear().col(0).z(), 0, 1e-12);  // level: the picture's x axis horizontal
    EXPECT_LT(p->camera.linear().col(1).z(), 0);           // and the world's up toward its top
  }
  // Half a turn: the axis on the shaft's other side (60 degrees from roll 0's), below it.
  EXPECT_NEAR(degrees_between(a.camera.linear().col(2), c.camera.linear().col(2)), 60, 1e-9);
  EXPECT_LT(c.camera.linear().col(2).z(), c.shaft.z());
  // A quarter turn, right-handed about the shaft: the axis swings from above the shaft toward
  // roll 0's picture right.
  const Vec3 right0 = a.camera.linear().col(0);
  EXPECT_GT(b.camera.linear().col(2).dot(right0), 0.4);
  EXPECT_NEAR(b.camera.linear().col(2).dot(right0), std::sin(30 * 3.14159265358979323846 / 180), 1e-9);
}

TEST(Endoscope, AShaftAlongTheVerticalTakesYAsThePicturesUp) {
  const EndoscopePose p = tools::endoscope_pose(Vec3(0, 0, 0.2), Vec3(0, 0, 0), 0.1, 0, 0);
  expect_rotation(p.camera);
  EXPECT_LT((p.camera.linear().col(2) - Vec3(0, 0, -1)).norm(), 1e-12);
  EXPECT_LT((p.camera.linear().col(1) - Vec3(0, -1, 0)).norm(), 1e-12);  // +y world toward the top
}

TEST(Endoscope, TheScriptMovesLookAtDepthAndRollLinearlyAndHoldsAfterwards) {
  EndoscopeDef def;
  def.port = Vec3(0, -0.1, 0.1);
  def.look_at = Vec3(0, 0, 0);
  def.depth = 0.04;
  def.angle_deg = 30;
  EndoscopeKeyframe k1;
  k1.t = 1.0;
  k1.look_at = Vec3(0.02, 0, 0);
  k1.depth = 0.06;
  EndoscopeKeyframe k2;
  k2.t = 3.0;
  k2.roll_deg = 40;  // look_at and depth held from k1
  def.script = {k1, k2};
  const EndoscopePose start = tools::endoscope_at(def, 0.0);
  EXPECT_LT((start.look_at - def.look_at).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(start.depth, 0.04);
  const EndoscopePose half = tools::endoscope_at(def, 0.5);
  EXPECT_LT((half.look_at - Vec3(0.01, 0, 0)).norm(), 1e-15);
  EXPECT_NEAR(half.depth, 0.05, 1e-15);
  EXPECT_DOUBLE_EQ(half.roll_deg, 0);
  const EndoscopePose mid = tools::endoscope_at(def, 2.0);
  EXPECT_LT((mid.look_at - Vec3(0.02, 0, 0)).norm(), 1e-15);
  EXPECT_NEAR(mid.depth, 0.06, 1e-15);
  EXPECT_NEAR(mid.roll_deg, 20, 1e-12);
  const EndoscopePose after = tools::endoscope_at(def, 10.0);
  EXPECT_NEAR(after.roll_deg, 40, 1e-12);
  // Every pose keeps the shaft through the port: the tip is on the port's line to look_at.
  for (double t : {0.0, 0.5, 1.7, 2.9, 10.0}) {
    const EndoscopePose p = tools::endoscope_at(def, t);
    const Vec3 along = (p.look_at - def.port).normalized();
    EXPECT_LT((p.tip - def.port - p.depth * along).norm(), 1e-14) << t;
  }
}

TEST(Endoscope, TheVerticalFieldOfViewFollowsTheAspect) {
  EXPECT_NEAR(tools::vertical_fov_deg(90, 1.0), 90, 1e-12);
  // tan(v / 2) = tan(h / 2) / aspect
  EXPECT_NEAR(std::tan(tools::vertical_fov_deg(70, 16.0 / 9.0) * 3.14159265358979323846 / 360.0),
              std::tan(35 * 3.14159265358979323846 / 180.0) * 9.0 / 16.0, 1e-12);
}

}  // namespace
