// Constraint contact with Coulomb friction against physics: sliding without friction, the
// friction law while sliding, sticking below the cone, a thin probe between nodes.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "engine/contact.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/organ_solver.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

// A 10 x 10 x 5 cm block (cells of `cell` m), its bottom fixed; its top at z = 0.
TissueModel block(double cell = 0.0025) {
  const int nx = static_cast<int>(std::lround(0.1 / cell)), nz = static_cast<int>(std::lround(0.05 / cell));
  TissueDef def = default_tissue(make_box(Vec3(0.1, 0.1, 0.05), nx, nx, nz, Vec3(0, 0, -0.025)));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.05 + 1e-9) def.fixed.row(i).setOnes();
  return scenario::build(def);
}

ContactSettings constraint(double mu) {
  ContactSettings cs;
  cs.method = ContactSettings::Method::constraint;
  cs.friction = mu;
  return cs;
}

// A vertical probe of radius r whose tip is at (x, y, -depth), moved by `motion` this step.
Capsule probe(double x, double y, double depth, double r, const Vec3& motion) {
  Capsule c;
  c.radius = r;
  c.p0 = Vec3(x, y, -depth + r);
  c.p1 = c.p0 + Vec3(0, 0, 0.1);
  c.motion = motion;
  return c;
}

bool verbose() { return std::getenv("VDM_VERBOSE") != nullptr; }

struct Slide {
  std::vector<ContactReport> press, slide;
};

// Presses the probe `depth` into the block at x = -2 cm in 10 steps, then slides it 4 cm along
// x in `steps` steps.
// `organ`: the model that solves the steps (null: VDM's engine on m).
Slide press_and_slide(const TissueModel& m, double mu, double depth, double r, int steps,
                      ContactSettings::Method method = ContactSettings::Method::constraint,
                      OrganSolver* organ = nullptr) {
  SimState s = make_sim_state(m);
  ContactSettings cs = constraint(mu);
  cs.method = method;
  ContactSolver contact(m, cs);
  if (organ) contact.set_solver(organ);
  const StepInput base = make_step_input(m);
  Slide out;
  ContactReport rep;
  const double x0 = -0.02;
  for (int j = 1; j <= 10; ++j) {
    contact.step(m, base, std::vector<Capsule>{probe(x0, 0, depth * j / 10, r, Vec3(0, 0, -depth / 10))}, s, rep);
    out.press.push_back(rep);
    if (verbose())
      std::printf("press %2d: F = %8.4f %8.4f %8.4f N, solves %d, pen %.3g, nodes %d, conv %d\n", j, rep.force.x(),
                  rep.force.y(), rep.force.z(), rep.solves, rep.max_penetration, rep.nodes, int(rep.converged));
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (int j = 1; j <= steps; ++j) {
    const double dx = 0.04 / steps;
    contact.step(m, base, std::vector<Capsule>{probe(x0 + dx * j, 0, depth, r, Vec3(dx, 0, 0))}, s, rep);
    out.slide.push_back(rep);
    if (verbose())
      std::printf("slide %2d: F = %8.4f %8.4f %8.4f N, solves %d, its %d, pen %.3g, nodes %d, conv %d\n", j,
                  rep.force.x(), rep.force.y(), rep.force.z(), rep.solves, rep.iterations, rep.max_penetration,
                  rep.nodes, int(rep.converged));
  }
  if (verbose())
    std::printf("slide: %.2f ms per step\n",
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / steps);
  EXPECT_LT(std::abs(s.volume_rel_error), 1e-9);
  return out;
}

// Steady sliding: every step converged, nothing deeper than `inside` times the probe's radius
// inside it, the normal force steady (from the 6th step on: the dent has formed around the
// moving probe).
void expect_steady(const Slide& run, double r, double inside = 0.02) {
  for (size_t j = 0; j < run.slide.size(); ++j) {
    const ContactReport& q = run.slide[j];
    EXPECT_TRUE(q.converged) << "slide step " << j;
    EXPECT_LE(q.max_penetration, inside * r) << "slide step " << j;
    if (j >= 5) {
      EXPECT_LT(std::abs(q.force.z() - run.slide[j - 1].force.z()), 0.1 * run.slide[j - 1].force.z())
          << "slide step " << j;
    }
  }
}

TEST(ConstraintContact, FrictionlessSlideHasNoTangentialForce) {
  // The probe of the friction test below (a 1 cm ball 2 mm deep), slid 4 cm without friction.
  const TissueModel m = block();
  const double r = 0.01;
  const Slide run = press_and_slide(m, 0.0, 0.002, r, 40);
  expect_steady(run, r);
  for (size_t j = 0; j < run.slide.size(); ++j) {
    const ContactReport& q = run.slide[j];
    EXPECT_GT(q.force.z(), 0.1);
    EXPECT_LE(std::abs(q.force.x()), 0.05 * q.force.z()) << "slide step " << j;
  }
}

// The elastic core on the block's surface (E 5 kPa, 5 mm cells), its bottom fixed.
std::unique_ptr<OrganSolver> core_on(const TissueModel& m) {
  core::CoreDef def;
  def.surface = m.rest;
  def.young_modulus = 5000;
  def.cell_size = 0.005;
  def.fixed = m.held;
  core::CoreModel model;
  std::string error;
  EXPECT_TRUE(core::build_core_model(def, model, error)) << error;
  return make_core_solver(std::move(model), 1.0 / 30);
}

TEST(ConstraintContact, FrictionlessSlideOnTheCoreHasNoTangentialForce) {
  // The same 1 cm probe, 2 mm deep, slid 4 cm over the elastic core without friction; and
  // with friction 0.3, once slipping, drag mu times the normal force.
  const TissueModel m = block();
  const double r = 0.01;
  for (const double mu : {0.0, 0.3}) {
    std::unique_ptr<OrganSolver> organ = core_on(m);
    const Slide run = press_and_slide(m, mu, 0.002, r, 20, ContactSettings::Method::constraint, organ.get());
    expect_steady(run, r);
    for (size_t j = 0; j < run.slide.size(); ++j) {
      const ContactReport& q = run.slide[j];
      EXPECT_GT(q.force.z(), 0.05) << "friction " << mu << ", slide step " << j;
      if (mu == 0) {
        EXPECT_LE(std::abs(q.force.x()), 0.05 * q.force.z()) << "slide step " << j;
      } else if (j >= 10) {
        EXPECT_NEAR(-q.force.x() / q.force.z(), mu, 0.2 * mu) << "slide step " << j;
      }
    }
  }
}

TEST(ConstraintContact, DeepFrictionlessSlideKeepsTheLaws) {
  // A 5 mm ball 4 mm deep over 2.5 mm cells: the contact patch is four cells across, and the
  // surface rides over the ball's front between the nodes (triangles take points of their
  // own there).
  const TissueModel m = block();
  const double r = 0.005;
  const Slide run = press_and_slide(m, 0.0, 0.004, r, 40);
  expect_steady(run, r);
  for (size_t j = 0; j < run.slide.size(); ++j) {
    const ContactReport& q = run.slide[j];
    EXPECT_GT(q.force.z(), 0.3);
    EXPECT_LE(std::abs(q.force.x()), 0.05 * q.force.z()) << "slide step " << j;
  }
}

TEST(ConstraintContact, SlidingWithFrictionDragsWithMuTimesTheNormalForce) {
  // A 1 cm ball-ended probe pressed 2 mm, slid 4 cm: once slipping (after 1 cm), the drag
  // over the normal force is mu (the contact normals tilt little at this depth).
  const TissueModel m = block();
  const double r = 0.01, mu = 0.3;
  const Slide run = press_and_slide(m, mu, 0.002, r, 40);
  expect_steady(run, r);
  for (size_t j = 10; j < run.slide.size(); ++j) {
    const ContactReport& q = run.slide[j];
    // The organ drags the probe back (-x) as it moves along +x.
    EXPECT_NEAR(-q.force.x() / q.force.z(), mu, 0.2 * mu) << "slide step " << j;
  }
}

// Presses a 5 mm probe 3 mm into the block at the origin, then pushes it sideways by `push`
// along x in `steps` steps, with friction mu. Returns the last report; `moved`: how far along
// x the top node under the probe's tip went.
ContactReport push_sideways(const TissueModel& m, double mu, double push, int steps, double& moved) {
  const double r = 0.005, depth = 0.003;
  SimState s = make_sim_state(m);
  ContactSolver contact(m, constraint(mu));
  const StepInput base = make_step_input(m);
  ContactReport rep;
  for (int j = 1; j <= 10; ++j)
    contact.step(m, base, std::vector<Capsule>{probe(0, 0, depth * j / 10, r, Vec3(0, 0, -depth / 10))}, s, rep);
  int tip = 0;
  for (int i = 1; i < m.n; ++i)
    if (m.rest.positions.row(i).squaredNorm() < m.rest.positions.row(tip).squaredNorm()) tip = i;
  const double before = s.u(tip, 0);
  for (int j = 1; j <= steps; ++j) {
    contact.step(m, base, std::vector<Capsule>{probe(push * j / steps, 0, depth, r, Vec3(push / steps, 0, 0))}, s, rep);
    EXPECT_TRUE(rep.converged) << "push step " << j;
  }
  moved = s.u(tip, 0) - before;
  return rep;
}

TEST(ConstraintContact, SmallSidewaysPushSticks) {
  const TissueModel m = block();
  const double mu = 0.5;
  double moved = 0.0;
  // 0.1 mm: below the cone, the tissue under the tip goes with the probe (5 mm ball).
  const ContactReport small = push_sideways(m, mu, 1e-4, 1, moved);
  EXPECT_LT(-small.force.x(), 0.9 * mu * small.force.z());
  EXPECT_GT(-small.force.x(), 0.0);
  // (to the contact solve's tolerance, half a percent of the probe's radius)
  EXPECT_NEAR(moved, 1e-4, ContactSettings().constraint_tolerance * 0.005) << "the tissue under the tip must move with the probe";
}

TEST(ConstraintContact, LargerSidewaysPushSlips) {
  // 2 cm along x in twenty steps: past the cone, the tip slides over the tissue. The tissue
  // that was under it lags far behind the probe, and the drag has reached the cone: at least
  // mu times the normal force (more, by what the ball's front ploughs: its normals tilt).
  const TissueModel m = block();
  const double mu = 0.5, push = 0.02;
  double moved = 0.0;
  const ContactReport large = push_sideways(m, mu, push, 20, moved);
  if (verbose())
    std::printf("pushed %.4g m: the tissue under the tip moved %.4g m, drag / normal %.3f\n", push, moved,
                -large.force.x() / large.force.z());
  EXPECT_LT(moved, 0.25 * push) << "the tissue under the tip must slip behind the probe";
  EXPECT_GT(moved, 0.0) << "friction drags the tissue along";
  EXPECT_GT(-large.force.x(), 0.95 * mu * large.force.z());
}

TEST(ConstraintContact, ThinProbeBetweenNodesMovesTheSurface) {
  // A 1 mm probe pressed 2 mm into a face with 5 mm edges, between the nodes: the triangles it
  // meets carry it (no node is inside it), with or without friction. Where the surface slides
  // off a point on the probe's tip, the triangle takes another where the tip meets it.
  const TissueModel m = block(0.005);
  const double r = 0.0005, depth = 0.002;
  const double x = 0.0021, y = 0.0013;  // inside a triangle, away from its nodes
  for (const double mu : {0.0, 0.2, 1.0}) {
    SimState s = make_sim_state(m);
    ContactSolver contact(m, constraint(mu));
    const StepInput base = make_step_input(m);
    ContactReport rep;
    for (int j = 1; j <= 10; ++j) {
      contact.step(m, base, std::vector<Capsule>{probe(x, y, depth * j / 10, r, Vec3(0, 0, -depth / 10))}, s, rep);
      if (verbose())
        std::printf("mu %.1f step %d: F %.4g N, solves %d, pen %.3g, nodes %d, conv %d\n", mu, j, rep.force.z(),
                    rep.solves, rep.max_penetration, rep.nodes, int(rep.converged));
      EXPECT_TRUE(rep.converged) << "mu " << mu << ", step " << j;
      EXPECT_LE(rep.max_penetration, 0.02 * r) << "mu " << mu << ", step " << j;
    }
    EXPECT_GT(rep.force.z(), 0.0) << "mu " << mu;
    // The nodes round the probe went down with the surface under it.
    double lowest = 0.0;
    for (int i = 0; i < m.n; ++i)
      if (std::hypot(m.rest.positions(i, 0) - x, m.rest.positions(i, 1) - y) < 0.006 && m.rest.positions(i, 2) > -1e-9)
        lowest = std::min(lowest, s.u(i, 2));
    EXPECT_LT(lowest, -0.5 * depth) << "mu " << mu;
  }
}

TEST(ConstraintContact, TheBroadPhaseDoesNotChangeTheResult) {
  // FCL's shape queries and the tree walk find the same triangles in other orders; the contact
  // points are put in one order, so the Gauss-Seidel, and the result, are the same bit for bit.
  const TissueModel m = block(0.005);
  const double r = 0.005;
  const StepInput base = make_step_input(m);
  SimState a = make_sim_state(m), b = make_sim_state(m);
  ContactSettings walk = constraint(0.3), shapes = constraint(0.3);
  shapes.fcl_shape_queries = true;
  ContactSolver ca(m, walk), cb(m, shapes);
  ContactReport ra, rb;
  for (int j = 1; j <= 12; ++j) {
    const Vec3 motion = j <= 6 ? Vec3(0, 0, -0.0005) : Vec3(0.001, 0, 0);
    const double x = j <= 6 ? 0.0011 : 0.0011 + 0.001 * (j - 6), depth = 0.0005 * std::min(j, 6);
    const std::vector<Capsule> tool{probe(x, 0.0007, depth, r, motion)};
    ca.step(m, base, tool, a, ra);
    cb.step(m, base, tool, b, rb);
    ASSERT_EQ(a.u, b.u) << "step " << j;
    EXPECT_EQ(ra.force, rb.force) << "step " << j;
  }
  EXPECT_GT(ra.force.z(), 0.0);
}

}  // namespace
}  // namespace vdm
