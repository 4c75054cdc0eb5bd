#include <gtest/gtest.h>

#include "engine/shapes.hpp"
#include "tools_scripted/grasp.hpp"

namespace tools {
namespace {

TEST(Grasp, ClosingHoldsTheNodesBetweenTheJawsAndTheyFollowTheFrame) {
  const vdm::SurfaceMesh ball = vdm::make_icosphere(0.05, 3);
  InstrumentDef def;
  def.type = InstrumentDef::Type::grasper;
  def.jaw_length = 0.015;
  def.grasp_width = 0.006;
  InstrumentPose pose;
  pose.tip = vdm::Vec3(0, 0, 0.047);
  pose.axis = vdm::Vec3(0, 0, -1);
  Grasp g;
  EXPECT_FALSE(g.update(def, pose, ball.positions));  // open: nothing happens
  EXPECT_TRUE(g.held().empty());
  pose.jaw_closed = true;
  EXPECT_TRUE(g.update(def, pose, ball.positions));
  ASSERT_FALSE(g.held().empty());
  for (int i : g.held()) EXPECT_GT(ball.positions(i, 2), 0.04);  // only the top of the ball
  // Lift and turn the grasper: held nodes move rigidly with it.
  InstrumentPose moved = pose;
  moved.tip += vdm::Vec3(0.01, 0, 0.02);
  moved.axis = vdm::Vec3(0.3, 0, -1).normalized();
  vdm::StepInput in;
  in.prescribed = vdm::FlagMat::Zero(ball.node_count(), 3);
  in.prescribed_u = vdm::NodeMat::Zero(ball.node_count(), 3);
  g.apply(moved, ball.positions, in);
  const Eigen::Isometry3d motion = jaw_frame(moved) * jaw_frame(pose).inverse();
  for (int i : g.held()) {
    EXPECT_EQ(in.prescribed.row(i).sum(), 3);
    const vdm::Vec3 expected = motion * vdm::Vec3(ball.positions.row(i).transpose());
    EXPECT_LT((ball.positions.row(i) + in.prescribed_u.row(i) - expected.transpose()).norm(), 1e-12);
  }
  pose.jaw_closed = false;
  EXPECT_TRUE(g.update(def, pose, ball.positions));
  EXPECT_TRUE(g.held().empty());
}

}  // namespace
}  // namespace tools
