// Hard cases with instruments (issue 7): deep presses, a squeeze between two probes, a probe
// starting inside the organ, two probes at once, a single-node grasp, a grasp released while
// moving. Label `long` (minutes under the sanitizers; about 1.5 s in a normal build).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/scene/mesh_io.hpp"
#include "engine/contact.hpp"
#include "support/hard_cases.hpp"
#include "support/scenarios.hpp"
#include "tools_scripted/grasp.hpp"

namespace vdm {
namespace {

using hard::expect_sensible;
using scenario::build;

Capsule probe(const Vec3& tip, const Vec3& axis, double radius, const Vec3& motion = Vec3::Zero()) {
  Capsule c;
  c.radius = radius;
  c.p0 = tip - radius * axis;        // axis: handle -> tip
  c.p1 = c.p0 - 0.2 * axis;
  c.motion = motion;
  return c;
}

// Deepest free node inside any capsule (m).
double free_penetration(const SimState& s, const ContactSolver& cs, const std::vector<Capsule>& tools) {
  double worst = 0;
  for (int i = 0; i < s.x.rows(); ++i) {
    if (cs.active()[i]) continue;
    for (const Capsule& c : tools) {
      Vec3 p, n;
      worst = std::max(worst, -capsule_distance(c, s.x.row(i).transpose(), p, n));
    }
  }
  return worst;
}

TissueModel ball(double R, int levels) {
  TissueDef def = default_tissue(make_icosphere(R, levels));
  return build(def);
}

TEST(HardInstruments, ProbePressedToHalfTheOrgansDepth) {
  const double R = 0.05, r = 0.008, step_m = 1e-3;
  const TissueModel m = ball(R, 4);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver cs(m);
  ContactReport rep;
  double last_force = 0;
  for (int k = 0; k <= 50; ++k) {  // 5 cm: half of the 10 cm depth
    const std::vector<Capsule> tools = {probe(Vec3(0, 0, R - k * step_m), -Vec3::UnitZ(), r,
                                              k ? Vec3(0, 0, -step_m) : Vec3::Zero())};
    cs.step(m, base, tools, s, rep);
    expect_sensible(m, s, 0.06, "depth " + std::to_string(k) + " mm");
    ASSERT_FALSE(HasFailure());
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "depth " << k;
    if (k > 0) {
      EXPECT_GE(rep.force.z(), last_force - 1e-9) << "force must not fall, depth " << k;
    }
    last_force = rep.force.z();
  }
  EXPECT_GT(last_force, 0.0);
}

TEST(HardInstruments, LiverSqueezedBetweenTwoProbes) {
  const auto path = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj";
  const vdmsim::MeshLoadResult mesh = vdmsim::load_surface_mesh(path.string());
  ASSERT_TRUE(mesh.ok) << mesh.error;
  const TissueModel m = build(default_tissue(mesh.mesh));
  // The right lobe's top and bottom above and below (x0, y0).
  const double x0 = 0.035, y0 = 0.0, r = 0.01;
  double top = -1, bottom = 1;
  for (int i = 0; i < m.n; ++i)
    if (std::hypot(m.rest.positions(i, 0) - x0, m.rest.positions(i, 1) - y0) < 0.01) {
      top = std::max(top, m.rest.positions(i, 2));
      bottom = std::min(bottom, m.rest.positions(i, 2));
    }
  ASSERT_GT(top - bottom, 0.05);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver cs(m);
  ContactReport rep;
  const double squeeze = 0.02, start = 0.002;  // each probe travels 2 cm in (4 cm of ~9)
  const int steps = 40;
  for (int k = 0; k <= steps; ++k) {
    const double d = -start + (squeeze + start) * k / steps, v = k ? (squeeze + start) / steps : 0.0;
    const std::vector<Capsule> tools = {probe(Vec3(x0, y0, top - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v)),
                                        probe(Vec3(x0, y0, bottom + d), Vec3::UnitZ(), r, Vec3(0, 0, v))};
    cs.step(m, base, tools, s, rep);
    expect_sensible(m, s, 0.05, "squeeze step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "step " << k;
  }
  // Both probes are pushed back; the net force is small against each (the organ is free).
  EXPECT_GT(rep.nodes, 0);
  EXPECT_GT(s.pressure, 0.0);
}

TEST(HardInstruments, ProbeStartingInsideTheOrganThenWithdrawn) {
  const double R = 0.05, r = 0.006;
  const TissueModel m = ball(R, 4);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver cs(m);
  ContactReport rep;
  const int steps = 40;
  for (int k = 0; k <= steps; ++k) {  // tip from the centre to 2 cm above the top
    const double tip = 0.07 * k / steps, v = k ? 0.07 / steps : 0.0;
    const std::vector<Capsule> tools = {probe(Vec3(0, 0, tip), -Vec3::UnitZ(), r, Vec3(0, 0, v))};
    cs.step(m, base, tools, s, rep);
    expect_sensible(m, s, 3 * r, "withdraw step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "step " << k;
  }
  // Out of the organ: back at rest (quasi-static, nothing else loads it).
  EXPECT_EQ(rep.nodes, 0);
  EXPECT_LT(s.u.cwiseAbs().maxCoeff(), 1e-6 * m.size);
}

TEST(HardInstruments, TwoProbesAtOnceGiveAMirrorSymmetricResult) {
  // Kinematic contact is a projection: mirror symmetric to round-off. Constraint contact with
  // friction is solved to its tolerance, each probe's contacts by their own Gauss-Seidel path,
  // so the stick and slip of the two sides may differ within it: symmetric within 2 % of the
  // probe's radius (the penetration allowed).
  const double R = 0.05, r = 0.006;
  const TissueModel m = ball(R, 4);
  using Method = ContactSettings::Method;
  for (const Method method : {Method::kinematic, Method::constraint}) {
    const bool exact = method == Method::kinematic;
    const std::string name = exact ? "kinematic" : "constraint";
    ContactSettings settings;
    settings.method = method;
    SimState s = make_sim_state(m);
    const StepInput base = make_step_input(m);
    ContactSolver cs(m, settings);
    ContactReport rep;
    const double x = 0.02, z0 = std::sqrt(R * R - x * x);
    for (int k = 0; k <= 15; ++k) {  // each 1.5 cm into the surface along -z
      const double d = 1e-3 * k, v = k ? 1e-3 : 0.0;
      const std::vector<Capsule> tools = {probe(Vec3(x, 0, z0 + 0.002 - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v)),
                                          probe(Vec3(-x, 0, z0 + 0.002 - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v))};
      cs.step(m, base, tools, s, rep);
      expect_sensible(m, s, 0.03, name + ", two probes step " + std::to_string(k));
      ASSERT_FALSE(HasFailure());
      EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << name << ", step " << k;
    }
    const Eigen::Matrix3d M = Vec3(-1, 1, 1).asDiagonal();
    const auto map = hard::mirror_map(m.rest.positions, M, 1e-9);
    const double umax = s.u.cwiseAbs().maxCoeff();
    double worst = 0.0;
    for (int i = 0; i < m.n; ++i) {
      ASSERT_GE(map[i], 0);
      worst = std::max(worst, (s.u.row(map[i]).transpose() - M * s.u.row(i).transpose()).norm());
    }
    EXPECT_GT(umax, 0.01) << name;
    EXPECT_LE(worst, exact ? 1e-6 * umax : 0.02 * r) << name;
    EXPECT_LT(std::abs(rep.force.x()), (exact ? 1e-6 : 0.02) * rep.force.norm()) << name << ": sideways forces cancel";
  }
}

tools::InstrumentDef grasper(double width) {
  tools::InstrumentDef g;
  g.type = tools::InstrumentDef::Type::grasper;
  g.jaw_length = 0.015;
  g.grasp_width = width;
  return g;
}

TEST(HardInstruments, GraspOfASingleNodeLiftedOneCentimetre) {
  const double R = 0.05;
  const TissueModel m = ball(R, 4);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  const int top = nearest_node(m.rest.positions, Vec3(0, 0, R));
  tools::InstrumentPose pose;
  pose.tip = m.rest.positions.row(top).transpose();
  pose.axis = -Vec3::UnitZ();
  pose.jaw_closed = true;
  tools::Grasp g;
  const auto def = grasper(1e-4);
  g.update(def, pose, s.x);
  ASSERT_EQ(g.held().size(), 1u);
  ASSERT_EQ(g.held()[0], top);
  for (int k = 1; k <= 20; ++k) {
    tools::InstrumentPose p = pose;
    p.tip += Vec3(0, 0, 0.01 * k / 20);
    in.clear();
    g.apply(p, m.rest.positions, in);
    step(m, in, s);
    expect_sensible(m, s, 0.0101, "single-node lift step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
  }
  EXPECT_NEAR(s.u(top, 2), 0.01, 1e-12);
  EXPECT_GT(s.reaction(top, 2), 0.0) << "the grasper pulls the node up";
}

TEST(HardInstruments, GraspReleasedMidMotionSpringsBackToRest) {
  const double R = 0.05;
  const TissueModel m = ball(R, 4);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  tools::InstrumentPose pose;
  pose.tip = Vec3(0, 0, R - 0.003);
  pose.axis = -Vec3::UnitZ();
  const auto def = grasper(0.006);
  tools::Grasp g;
  for (int k = 0; k <= 30; ++k) {
    pose.tip += Vec3(0.0005, 0, 0.001);  // moving up and sideways the whole time
    pose.jaw_closed = k >= 1 && k < 15;  // opens at step 15, still moving
    g.update(def, pose, s.x);
    in.clear();
    g.apply(pose, m.rest.positions, in);
    step(m, in, s);
    expect_sensible(m, s, 0.03, "grasp step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    if (k == 14) {
      EXPECT_GT(s.u.cwiseAbs().maxCoeff(), 0.01) << "it was holding";
    }
    if (k >= 15) {
      EXPECT_TRUE(g.held().empty());
    }
  }
  EXPECT_LT(s.u.cwiseAbs().maxCoeff(), 1e-6 * m.size) << "released: back at rest";
}

}  // namespace
}  // namespace vdm
