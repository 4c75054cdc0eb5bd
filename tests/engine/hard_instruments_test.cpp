// Hard cases with instruments (issue 7): deep presses, a squeeze between two probes, a probe
// starting inside the organ, two probes at once, a single-node grasp, a grasp released while
// moving; and solver trouble: fallbacks and clean failure.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/mesh_io.hpp"
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
  const double R = 0.05, r = 0.006;
  const TissueModel m = ball(R, 4);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver cs(m);
  ContactReport rep;
  const double x = 0.02, z0 = std::sqrt(R * R - x * x);
  for (int k = 0; k <= 15; ++k) {  // each 1.5 cm into the surface along -z
    const double d = 1e-3 * k, v = k ? 1e-3 : 0.0;
    const std::vector<Capsule> tools = {probe(Vec3(x, 0, z0 + 0.002 - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v)),
                                        probe(Vec3(-x, 0, z0 + 0.002 - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v))};
    cs.step(m, base, tools, s, rep);
    expect_sensible(m, s, 0.03, "two probes step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "step " << k;
  }
  const Eigen::Matrix3d M = Vec3(-1, 1, 1).asDiagonal();
  const auto map = hard::mirror_map(m.rest.positions, M, 1e-9);
  const double umax = s.u.cwiseAbs().maxCoeff();
  int asym = 0;
  for (int i = 0; i < m.n; ++i) {
    ASSERT_GE(map[i], 0);
    if ((s.u.row(map[i]).transpose() - M * s.u.row(i).transpose()).norm() > 1e-6 * umax) ++asym;
  }
  EXPECT_EQ(asym, 0);
  EXPECT_LT(std::abs(rep.force.x()), 1e-6 * rep.force.norm()) << "sideways forces cancel";
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
  const int top = hard::nearest_node(m.rest.positions, Vec3(0, 0, R));
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

// Solver trouble.

TissueModel pressed_cube_model(SolverMethod method, int max_iterations) {
  TissueDef def = scenario::cube_on_table(0.1, 5, method);
  def.solver.max_iterations = max_iterations;
  return build(def);
}

TEST(SolverTrouble, NonConvergedIterativeSolvesFallBackToTheDirectSolver) {
  const double L = 0.1;
  const TissueModel direct = pressed_cube_model(SolverMethod::direct, 2000);
  for (SolverMethod method : {SolverMethod::structured, SolverMethod::reference}) {
    const TissueModel m = pressed_cube_model(method, 1);  // one Krylov iteration: never converges
    SimState s = make_sim_state(m), ref = make_sim_state(direct);
    StepInput in = make_step_input(m);
    for (int k = 1; k <= 5; ++k) {
      scenario::press_top(m, L, -0.004 * k, in);
      step(m, in, s);
      step(direct, in, ref);
      ASSERT_FALSE(s.failed) << s.failure;
      EXPECT_EQ(s.stats.fallbacks, 1) << to_string(method) << " step " << k;
      ASSERT_NE(s.stats.fallback, nullptr);
      EXPECT_NE(std::string(s.stats.fallback).find("did not converge"), std::string::npos);
      EXPECT_TRUE(s.stats.converged);
      EXPECT_LT((s.u - ref.u).cwiseAbs().maxCoeff(), 1e-9 * ref.u.cwiseAbs().maxCoeff()) << to_string(method);
    }
    EXPECT_EQ(s.stats.total_fallbacks, 5);
    EXPECT_FALSE(s.warnings.empty());
  }
}

TEST(SolverTrouble, ConvergedSolvesDoNotFallBack) {
  const TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, 0.1, -0.01, in);
  step(m, in, s);
  EXPECT_EQ(s.stats.fallbacks, 0);
  EXPECT_EQ(s.stats.fallback, nullptr);
}

TEST(SolverTrouble, AStepThatNoSolverCanDoFailsCleanlyAndChangesNothing) {
  TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, 0.1, -0.005, in);
  step(m, in, s);
  ASSERT_FALSE(s.failed);
  const NodeMat u = s.u;
  const double p = s.pressure;
  m.bulk(3, 0) = std::nan("");  // a corrupted model: every solver gets NaN
  scenario::press_top(m, 0.1, -0.01, in);
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("no solver"), std::string::npos) << s.failure;
  EXPECT_EQ(s.step, 1);
  EXPECT_EQ(s.u, u);
  EXPECT_EQ(s.pressure, p);
}

TEST(SolverTrouble, MalformedInputFailsTheStepWithAReason) {
  const TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  in.prescribed(5, 2) = 1;
  in.prescribed_u(5, 2) = std::nan("");
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("prescribed_u is not finite"), std::string::npos) << s.failure;
  EXPECT_EQ(s.step, 0);
  in.prescribed_u = NodeMat::Zero(3, 3);  // wrong size (used to be read out of bounds)
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("prescribed_u has the wrong number of rows"), std::string::npos) << s.failure;
  in = make_step_input(m);
  step(m, in, s);
  EXPECT_FALSE(s.failed) << "a good input clears the failure";
  EXPECT_TRUE(s.failure.empty());
}

TEST(Rewind, ResolvingAStepGivesTheSameStateAsSolvingItOnce) {
  // With a refresh period and nonlinear iterations, the geometry, matrices and refresh
  // counter are part of what a re-solve must restore (contact's active set re-solves).
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 4);
  def.solver.refresh_every = 3;
  def.solver.nonlinear_iterations = 3;
  def.use_gravity = true;
  const TissueModel m = build(def);
  SimState a = make_sim_state(m), b = make_sim_state(m);
  StepInput in = make_step_input(m), other = make_step_input(m);
  for (int k = 1; k <= 7; ++k) {
    scenario::press_top(m, L, -0.003 * k, in);
    scenario::press_top(m, L, -0.02, other);
    step(m, in, a);
    step(m, other, b);  // a different attempt first...
    rewind_step(m, b);
    step(m, in, b);     // ...then the real one
    EXPECT_EQ(a.step, b.step);
    // Equal up to the iterative solver's tolerance (its warm starts differ).
    EXPECT_LT((a.u - b.u).cwiseAbs().maxCoeff(), 1e-9 * L) << "step " << k;
    EXPECT_LT((a.area_vectors - b.area_vectors).cwiseAbs().maxCoeff(), 1e-9 * a.area_vectors.cwiseAbs().maxCoeff())
        << "step " << k;
    EXPECT_EQ(a.stats.refreshed, b.stats.refreshed) << "step " << k;
  }
}

TEST(Refresh, BetweenRefreshesGravityUsesOneGeometry) {
  // Loads between refreshes come from the refresh's surface (area vectors and depths): the
  // hydrostatic load is then exactly the weight of that surface's volume, so a hung organ's
  // steady state does not depend on which step of the period it is measured at.
  TissueDef def = default_tissue(make_icosphere(0.05, 3));
  def.use_gravity = true;
  def.connectivity_modulus = 200;
  def.bulk = 2000;
  def.solver.refresh_every = 1000;  // never after the first
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  const StepInput in = make_step_input(m);
  step(m, in, s);
  const NodeMat u1 = s.u;
  for (int k = 0; k < 5; ++k) step(m, in, s);
  // The matrix, the loads and the volume row are all at the rest geometry: the same system,
  // up to the Newton term of the volume row (second order).
  EXPECT_LT((s.u - u1).cwiseAbs().maxCoeff(), 1e-3 * u1.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace vdm
