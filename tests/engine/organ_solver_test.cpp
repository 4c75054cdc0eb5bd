// The organ solvers as contact uses them, on every model (vdm, fem, mass_spring): rewind()
// puts the state back at the step's start, start_u() says where the step started, a step
// solved again from there reaches the same equilibrium; and constraint contact runs on the
// FEM reference (a ball pressing a block: its force close to kinematic contact's on the same
// model, the surface outside the ball, every step converged).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "engine/contact.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/elastic_moduli.hpp"
#include "engine/fem/fem_model.hpp"
#include "engine/fem/tet_mesh.hpp"
#include "engine/organ_solver.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

constexpr double kYoung = 3000, kPoisson = 0.45;
// A 10 x 10 x 5 cm block, 6 x 6 x 3 cells (a finer one makes the FEM's steps too slow here).
const Vec3 kSize(0.1, 0.1, 0.05), kCentre(0, 0, -0.025);  // the block's top at z = 0
constexpr int kCells = 6, kLayers = 3;

bool verbose() { return std::getenv("VDM_VERBOSE") != nullptr; }

// The block's surface, its bottom fixed, with VDM's moduli for E and nu.
TissueModel block_surface() {
  TissueDef def = default_tissue(make_box(kSize, kCells, kCells, kLayers, kCentre));
  const VdmModuli moduli = vdm_moduli_from_elastic(kYoung, kPoisson);
  def.bulk = moduli.bulk;
  def.connectivity_modulus = moduli.connectivity;
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -kSize.z() + 1e-9) def.fixed.row(i).setOnes();
  return scenario::build(def);
}

// A solver of `kind` for the block (a fresh one: each keeps its own state).
std::unique_ptr<OrganSolver> make_solver(ModelKind kind, const TissueModel& surface) {
  std::string error;
  switch (kind) {
    case ModelKind::vdm: return make_vdm_solver(surface);
    case ModelKind::fem: {
      fem::FemDef def;
      def.mesh = fem::make_box_tets(kSize, kCells, kCells, kLayers, kCentre);
      def.young_modulus = kYoung;
      def.poisson_ratio = kPoisson;
      def.fixed = surface.held;
      fem::FemModel model;
      EXPECT_TRUE(fem::build_fem_model(def, model, error)) << error;
      return make_fem_solver(std::move(model), 1.0);
    }
    case ModelKind::vdm_core: {
      core::CoreDef def;
      def.surface = surface.rest;
      def.young_modulus = kYoung;
      def.cell_size = 0.01;
      def.fixed = surface.held;
      core::CoreModel model;
      EXPECT_TRUE(core::build_core_model(def, model, error)) << error;
      return make_core_solver(std::move(model), 1.0);
    }
    case ModelKind::mass_spring: {
      MassSpringDef def;
      def.positions = surface.rest.positions;
      def.triangles = surface.rest.triangles;
      def.young_modulus = kYoung;
      def.volume_modulus = 10 * kYoung;
      def.fixed = surface.held;
      MassSpringModel model;
      EXPECT_TRUE(build_mass_spring_model(def, model, error)) << error;
      return make_mass_spring_solver(std::move(model), 1.0);
    }
  }
  return nullptr;
}

// The top's nodes within 2 cm of its centre pushed down `depth`.
StepInput press(const TissueModel& m, double depth) {
  StepInput in = make_step_input(m);
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 2) > -1e-9 && m.rest.positions.row(i).head<2>().norm() < 0.02) {
      in.prescribed.row(i).setOnes();
      in.prescribed_u(i, 2) = -depth;
    }
  return in;
}

class EveryModel : public testing::TestWithParam<ModelKind> {};

TEST_P(EveryModel, RewindPutsTheStateBackWhereTheStepStarted) {
  const TissueModel m = block_surface();
  const std::unique_ptr<OrganSolver> solver = make_solver(GetParam(), m);
  SimState s = make_sim_state(m);
  // Before any step, the start is the state itself.
  EXPECT_EQ(solver->start_u(s), s.u);
  solver->step(press(m, 0.002), s);
  ASSERT_FALSE(s.failed) << s.failure;
  const NodeMat u1 = s.u, x1 = s.x, v1 = s.velocity;
  const long step1 = s.step;
  const double time1 = s.time;
  ASSERT_GT(u1.cwiseAbs().maxCoeff(), 1e-3);  // it moved

  solver->trial_step(press(m, 0.004), s, StepResults::reactions);
  solver->finish_step(s);
  ASSERT_FALSE(s.failed) << s.failure;
  const NodeMat u2 = s.u;
  EXPECT_EQ(s.step, step1 + 1);
  EXPECT_EQ(solver->start_u(s), u1);  // where this step started, exactly
  solver->rewind(s);
  EXPECT_EQ(s.u, u1);
  EXPECT_EQ(s.x, x1);
  EXPECT_EQ(s.velocity, v1);
  EXPECT_EQ(s.step, step1);
  EXPECT_EQ(s.time, time1);
  EXPECT_EQ(solver->start_u(s), u1);

  // The same step solved again from there: the same equilibrium (the reference models start
  // their iteration from their last solution, so within their solvers' tolerance: vdm_core's
  // stops within 1e-4 of the organ's size of its answer, here 1e-3 of the press).
  solver->step(press(m, 0.004), s);
  ASSERT_FALSE(s.failed) << s.failure;
  const double share = GetParam() == ModelKind::vdm_core ? 5e-3 : 1e-6;
  EXPECT_LT((s.u - u2).cwiseAbs().maxCoeff(), share * u2.cwiseAbs().maxCoeff());
  EXPECT_EQ(s.step, step1 + 1);
}

INSTANTIATE_TEST_SUITE_P(OrganSolver, EveryModel, testing::Values(ModelKind::vdm, ModelKind::fem, ModelKind::mass_spring, ModelKind::vdm_core),
                         [](const testing::TestParamInfo<ModelKind>& p) { return std::string(to_string(p.param)); });

struct Pressed {
  std::vector<ContactReport> steps;
  double deepest_node = 0;  // the deepest surface node inside the ball after the last step (m)
};

// A ball of radius r (a capsule's end) pressed `depth` into the top's centre in `steps` steps,
// on `kind` with contact `method`.
Pressed press_ball(ModelKind kind, ContactSettings::Method method, double mu, double r, double depth, int steps) {
  const TissueModel m = block_surface();
  const std::unique_ptr<OrganSolver> solver = make_solver(kind, m);
  SimState s = make_sim_state(m);
  ContactSettings cs;
  cs.method = method;
  cs.friction = mu;
  ContactSolver contact(m, cs);
  if (kind != ModelKind::vdm) contact.set_solver(solver.get());
  const StepInput base = make_step_input(m);
  Pressed out;
  Capsule ball;
  ball.radius = r;
  for (int j = 1; j <= steps; ++j) {
    ball.p0 = Vec3(0, 0, r - depth * j / steps);
    ball.p1 = ball.p0 + Vec3(0, 0, 0.1);
    ball.motion = Vec3(0, 0, -depth / steps);
    ContactReport rep;
    contact.step(m, base, std::vector<Capsule>{ball}, s, rep);
    EXPECT_FALSE(s.failed) << s.failure;
    out.steps.push_back(rep);
    if (verbose())
      std::printf("%s %s step %d: F = %8.4f %8.4f %8.4f N, solves %d, nodes %d, inside %.3g mm, converged %d\n",
                  to_string(kind), method == ContactSettings::Method::constraint ? "constraint" : "kinematic", j,
                  rep.force.x(), rep.force.y(), rep.force.z(), rep.solves, rep.nodes, 1e3 * rep.max_penetration,
                  int(rep.converged));
  }
  Vec3 p, n;
  for (int i = 0; i < m.n; ++i) out.deepest_node = std::max(out.deepest_node, -capsule_distance(ball, s.x.row(i).transpose(), p, n));
  return out;
}

// Frictionless constraint contact on the FEM reference and on the elastic core. (mass_spring
// is left out: its flat top, springs in its own plane, has no stiffness across it to first
// order, and both methods find about no force there.)
void expect_constraint_like_kinematic(ModelKind kind) {
  const double r = 0.025, depth = 0.006;
  const int steps = 4;
  const Pressed kin = press_ball(kind, ContactSettings::Method::kinematic, 0, r, depth, steps);
  const Pressed con = press_ball(kind, ContactSettings::Method::constraint, 0, r, depth, steps);
  for (int j = 0; j < steps; ++j) {
    const ContactReport& c = con.steps[static_cast<size_t>(j)];
    EXPECT_TRUE(c.converged) << "step " << j;
    EXPECT_GT(c.nodes, 0) << "step " << j;
    EXPECT_LE(c.max_penetration, 0.02 * r) << "step " << j;  // the surface stays outside the ball
    EXPECT_LT(c.solves, 10) << "step " << j;
    // The organ pushes the ball up, the harder the deeper.
    EXPECT_GT(c.force.z(), 0.0) << "step " << j;
    if (j > 0) {
      EXPECT_GT(c.force.z(), con.steps[static_cast<size_t>(j - 1)].force.z()) << "step " << j;
    }
  }
  EXPECT_LE(con.deepest_node, 0.02 * r);
  // At the deepest step not below kinematic contact's force (kinematic contact holds the nodes
  // only, and lets the triangles between them into the ball; constraint contact also holds
  // the triangles' points); on the FEM, with five nodes under the ball, close to it. (The
  // core's kinematic contact holds four: its rim sinks faster than the FEM's.)
  const double k = kin.steps.back().force.z(), c = con.steps.back().force.z();
  EXPECT_GE(c, k);
  if (kind == ModelKind::fem) {
    EXPECT_EQ(kin.steps.back().nodes, 5);
    EXPECT_LE(c, 1.25 * k);
  }
  std::printf("%s: kinematic %.4f N, constraint %.4f N\n", to_string(kind), k, c);
}

TEST(OrganSolverStress, CoreComputesTheStressOnlyWhenAsked) {
  // A scene turns the surface stress off for a frame's sub-steps before its last: a step
  // without it leaves the state's stress as it was, and the next step with it gives the
  // stress a solver that computed it at every step gives.
  const TissueModel m = block_surface();
  core::CoreDef def;
  def.surface = m.rest;
  def.young_modulus = kYoung;
  def.cell_size = 0.01;
  def.fixed = m.held;
  def.compute_stress = true;
  core::CoreModel model;
  std::string error;
  ASSERT_TRUE(core::build_core_model(def, model, error)) << error;
  const std::unique_ptr<OrganSolver> every = make_core_solver(model, 1.0), last = make_core_solver(model, 1.0);
  SimState a = make_sim_state(m), b = make_sim_state(m);
  every->step(press(m, 0.002), a);
  last->set_surface_stress(false);
  last->step(press(m, 0.002), b);
  ASSERT_FALSE(a.failed || b.failed);
  EXPECT_GT(a.stress.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(b.stress.cwiseAbs().maxCoeff(), 0.0) << "not computed";
  EXPECT_EQ(a.u, b.u) << "the step itself is the same";
  every->step(press(m, 0.004), a);
  last->set_surface_stress(true);
  last->step(press(m, 0.004), b);
  EXPECT_EQ(a.u, b.u);
  EXPECT_EQ(a.stress, b.stress);
  EXPECT_EQ(a.strain, b.strain);
}

TEST(OrganSolverContact, ConstraintContactPressesTheFemBlockLikeKinematicContact) {
  expect_constraint_like_kinematic(ModelKind::fem);
}

TEST(OrganSolverContact, ConstraintContactPressesTheCoreBlockLikeKinematicContact) {
  expect_constraint_like_kinematic(ModelKind::vdm_core);
}

}  // namespace
}  // namespace vdm
