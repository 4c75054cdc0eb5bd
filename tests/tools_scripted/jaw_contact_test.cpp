// Grasper jaws are boxes in contact: opening or closing beside an organ they push its surface
// instead of passing through it; the shaft collides too; grasped nodes take no part in
// contact.
#include <gtest/gtest.h>

#include "engine/contact.hpp"
#include "support/scenarios.hpp"
#include "tools_scripted/grasp.hpp"

namespace tools {
namespace {

// Deepest node of x inside the shape (m, 0 when none is inside).
double deepest(const vdm::ToolShape& t, const vdm::NodeMat& x) {
  double d = 0;
  for (int i = 0; i < x.rows(); ++i) {
    vdm::Vec3 p, n;
    d = std::max(d, -vdm::tool_distance(t, x.row(i).transpose(), p, n));
  }
  return d;
}

// A ball of radius R (2562 nodes) fixed at its bottom.
vdm::TissueModel ball_on_base(double R) {
  vdm::TissueDef def = vdm::default_tissue(vdm::make_icosphere(R, 4));
  const int n = def.mesh.node_count();
  def.fixed = vdm::FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.8 * R) def.fixed.row(i).setOnes();
  return vdm::scenario::build(def);
}

TEST(JawContact, JawsOpeningBesideABallPushItsSurface) {
  const double R = 0.05;
  const vdm::TissueModel m = ball_on_base(R);
  InstrumentDef g;
  g.type = InstrumentDef::Type::grasper;
  g.radius = 0.005;
  g.jaw_length = 0.015;
  // Pointing down beside the ball at its equator, the lower jaw's outer face 0.5 mm from the
  // surface; the lower jaw opens toward the ball.
  InstrumentPose pose;
  pose.axis = vdm::Vec3(0, 0, -1);
  const vdm::Vec3 y = instrument_frame(pose).linear().col(1);
  pose.tip = (R + 2 * jaw_half_size(g).y() + 0.0005) * y;
  pose.jaw_opening = 0;
  // Without contact, the opened lower jaw would cut through the ball at rest: its tip's
  // outer corner ends this deep inside the ball, and rest nodes lie inside the jaw.
  InstrumentPose open = pose;
  open.jaw_opening = 1;
  const vdm::ToolShape open_jaw = jaw_shape(g, open, open, -1);
  const vdm::Vec3 corner = open_jaw.pose * vdm::Vec3(0, -open_jaw.half_size.y(), open_jaw.half_size.z());
  const double through = R - corner.norm();
  EXPECT_GT(through, 0.003);
  EXPECT_GT(deepest(open_jaw, m.rest.positions), 0.0);

  vdm::SimState s = vdm::make_sim_state(m);
  const vdm::StepInput base = vdm::make_step_input(m);
  vdm::ContactSolver contact(m);
  vdm::ContactReport rep;
  InstrumentPose prev = pose;
  double last_push = 0;
  for (int k = 1; k <= 10; ++k) {
    InstrumentPose now = pose;
    now.jaw_opening = k / 10.0;
    const std::vector<vdm::ToolShape> jaws = {jaw_shape(g, now, prev, +1), jaw_shape(g, now, prev, -1)};
    contact.step(m, base, jaws, s, rep);
    ASSERT_FALSE(s.failed);
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-4) << "opening " << now.jaw_opening;
    for (const vdm::ToolShape& j : jaws) EXPECT_LE(deepest(j, s.x), 0.02 * j.size()) << "opening " << now.jaw_opening;
    // The ball pushes back on the jaw, toward +y; the surface moves away from the jaw (-y).
    const double push = -(s.u * y).minCoeff();
    if (k > 5) {
      EXPECT_GT(rep.nodes, 0);
      EXPECT_GT(rep.force.dot(y), 0.0);
      EXPECT_GE(push, last_push - 1e-9);
    }
    last_push = push;
    prev = now;
  }
  EXPECT_GT(last_push, 0.6 * through) << "the surface went away from the jaw";
  std::printf("jaw opening beside a ball: jaw tip %.2f mm inside the ball without contact; surface pushed %.2f mm, force %.3f N\n",
              through * 1e3, last_push * 1e3, rep.force.dot(y));
}

TEST(JawContact, JawsClosingOnTheOrganPushItAndStayOut) {
  // An open grasper pointing down at the top of a ball, its jaws' tips just above it: closing,
  // the jaws swing down and in, and closed they would reach below the surface. With contact
  // the top is pushed down and no node ends inside a jaw.
  const double R = 0.05;
  const vdm::TissueModel m = ball_on_base(R);
  InstrumentDef g;
  g.type = InstrumentDef::Type::grasper;
  g.radius = 0.005;
  g.jaw_length = 0.015;
  InstrumentPose pose;
  pose.axis = vdm::Vec3(0, 0, -1);
  pose.tip = vdm::Vec3(0, 0, R - 0.0025);
  pose.jaw_opening = 1;
  const vdm::Vec3 y = vdm::Vec3::UnitZ();  // the direction the organ pushes the jaws
  InstrumentPose closed = pose;
  closed.jaw_opening = 0;
  // How far a jaw's tip end reaches inside the ball at rest (negative: outside).
  auto reach = [&](const InstrumentPose& p, int side) {
    const vdm::ToolShape jaw = jaw_shape(g, p, p, side);
    double most = -1.0;
    for (double cx : {-1.0, 1.0})
      for (double cy : {-1.0, 1.0})
        most = std::max(most, R - (jaw.pose * vdm::Vec3(cx * jaw.half_size.x(), cy * jaw.half_size.y(), jaw.half_size.z())).norm());
    return most;
  };
  double through = 0.0;
  for (int side : {+1, -1}) {
    EXPECT_LT(reach(pose, side), 0.0) << "open jaws start outside";
    EXPECT_GT(reach(closed, side), 0.001) << "closed they reach inside";
    through = std::max(through, reach(closed, side));
  }
  using Method = vdm::ContactSettings::Method;
  for (const Method method : {Method::constraint, Method::kinematic}) {
    const bool sticks = method == Method::kinematic;
    vdm::ContactSettings settings;
    settings.method = method;
    vdm::SimState s = vdm::make_sim_state(m);
    const vdm::StepInput base = vdm::make_step_input(m);
    vdm::ContactSolver contact(m, settings);
    vdm::ContactReport rep;
    InstrumentPose prev = pose;
    double last_push = 0;
    for (int k = 0; k <= 10; ++k) {
      InstrumentPose now = pose;
      now.jaw_opening = 1.0 - k / 10.0;
      const std::vector<vdm::ToolShape> tools = {jaw_shape(g, now, prev, +1), jaw_shape(g, now, prev, -1),
                                                 shaft_shape(g, now, prev)};
      contact.step(m, base, tools, s, rep);
      const std::string at = std::string(sticks ? "kinematic" : "constraint") + ", opening " +
                             std::to_string(now.jaw_opening);
      ASSERT_FALSE(s.failed) << at;
      EXPECT_LT(std::abs(s.volume_rel_error), 1e-4) << at;
      for (const vdm::ToolShape& t : tools) EXPECT_LE(deepest(t, s.x), 0.02 * t.size()) << at;
      const double push = -(s.u * y).minCoeff();
      // Held on the jaws, the surface only goes further down as they swing in; sliding, it
      // may slip along a jaw's face and rise a little between frames.
      if (sticks) {
        EXPECT_GE(push, last_push - 1e-9) << at;
      }
      last_push = push;
      prev = now;
    }
    EXPECT_GT(rep.nodes, 0);
    EXPECT_GT(rep.force.dot(y), 0.0);  // the ball pushes the jaw back, toward +y
    EXPECT_GT(last_push, 0.5 * through);
  }
}

TEST(JawContact, TheShaftCollides) {
  // A grasper lowered onto the ball lying on its side: the shaft, not the jaws, meets the top.
  const double R = 0.05;
  const vdm::TissueModel m = ball_on_base(R);
  InstrumentDef g;
  g.type = InstrumentDef::Type::grasper;
  g.radius = 0.005;
  g.length = 0.2;
  g.jaw_length = 0.015;
  InstrumentPose pose;
  pose.axis = vdm::Vec3(1, 0, 0);  // horizontal: tip at +x, shaft back along -x
  pose.jaw_opening = 0;
  vdm::SimState s = vdm::make_sim_state(m);
  const vdm::StepInput base = vdm::make_step_input(m);
  vdm::ContactSolver contact(m);
  vdm::ContactReport rep;
  InstrumentPose prev = pose;
  prev.tip = vdm::Vec3(0.08, 0, R + g.radius + 0.001);
  for (int k = 0; k <= 5; ++k) {
    InstrumentPose now = pose;
    now.tip = vdm::Vec3(0.08, 0, R + g.radius + 0.001 - 0.001 * k);  // the jaws are beyond the ball
    const std::vector<vdm::ToolShape> tools = {jaw_shape(g, now, prev, +1), jaw_shape(g, now, prev, -1),
                                               shaft_shape(g, now, prev)};
    contact.step(m, base, tools, s, rep);
    ASSERT_FALSE(s.failed);
    EXPECT_LE(deepest(tools[2], s.x), 0.02 * tools[2].size());
    prev = now;
  }
  EXPECT_GT(rep.nodes, 0);
  EXPECT_GT(rep.force.z(), 0.0);  // pushed up by the ball
  EXPECT_LT(s.u.col(2).minCoeff(), -0.003);
}

TEST(JawContact, GraspedNodesTakeNoPartInContact) {
  // Nodes prescribed on all axes (as grasped nodes are) stay where the grasp puts them even
  // inside a jaw; the same nodes free are pushed out.
  const vdm::TissueModel m = vdm::scenario::build(vdm::default_tissue(vdm::make_icosphere(0.05, 3)));
  InstrumentDef g;
  g.type = InstrumentDef::Type::grasper;
  g.radius = 0.005;
  g.jaw_length = 0.015;
  g.grasp_width = 0.006;
  InstrumentPose pose;
  pose.tip = vdm::Vec3(0, 0, 0.047);
  pose.axis = vdm::Vec3(0, 0, -1);
  pose.jaw_closed = true;
  pose.jaw_opening = 0;
  Grasp grasp;
  grasp.update(g, pose, m.rest.positions);
  ASSERT_FALSE(grasp.held().empty());
  vdm::StepInput base = vdm::make_step_input(m);
  grasp.apply(pose, m.rest.positions, base);
  const std::vector<vdm::ToolShape> jaws = {jaw_shape(g, pose, pose, +1), jaw_shape(g, pose, pose, -1)};
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::ContactSolver contact(m);
  vdm::ContactReport rep;
  contact.step(m, base, jaws, s, rep);
  ASSERT_FALSE(s.failed);
  for (int i : grasp.held()) {
    EXPECT_FALSE(contact.active()[i]) << i;
    EXPECT_LT((s.u.row(i) - base.prescribed_u.row(i)).norm(), 1e-12) << i;
  }
}

}  // namespace
}  // namespace tools
