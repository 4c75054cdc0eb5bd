// Kinematic probe contact against analytic geometry and physics.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "engine/contact.hpp"
#include "engine/convex_hull.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

Capsule vertical_probe(double tip_z, double radius, double motion_z = 0.0) {
  Capsule c;
  c.radius = radius;
  c.p0 = Vec3(0, 0, tip_z + radius);
  c.p1 = c.p0 + Vec3(0, 0, 0.2);
  c.motion = Vec3(0, 0, motion_z);
  return c;
}

TEST(CapsuleDistance, AnalyticCases) {
  const Capsule c = vertical_probe(0.0, 0.01);
  Vec3 p, n;
  EXPECT_NEAR(capsule_distance(c, Vec3(0, 0, -0.005), p, n), 0.005, 1e-15);  // below the tip
  EXPECT_LT((n - Vec3(0, 0, -1)).norm(), 1e-12);
  EXPECT_NEAR(capsule_distance(c, Vec3(0.03, 0, 0.1), p, n), 0.02, 1e-15);  // beside the shaft
  EXPECT_LT((p - Vec3(0.01, 0, 0.1)).norm(), 1e-15);
  EXPECT_NEAR(capsule_distance(c, Vec3(0.004, 0, 0.1), p, n), -0.006, 1e-15);  // inside
}

TEST(PushOut, AheadOfTheProbeAndBehindIt) {
  const Capsule c = vertical_probe(0.0, 0.004, -0.001);
  Vec3 dir;
  // A node the descending probe ran into goes down to the tip, not round it.
  const Vec3 a = push_out(c, Vec3(0.001, 0, 0.001), -c.motion, dir);
  EXPECT_NEAR(a.x(), 0.001, 1e-12);
  Vec3 p, n;
  EXPECT_NEAR(capsule_distance(c, a, p, n), 0.0, 1e-12);
  EXPECT_LT(a.z(), 0.001);
  // A node that sprang up into the tip from below is pushed back down onto it.
  const Vec3 b = push_out(c, Vec3(0, 0, 0.002), Vec3(0, 0, 0.01), dir);
  EXPECT_NEAR(b.z(), 0.0, 1e-12);
  EXPECT_LT((dir - Vec3(0, 0, -1)).norm(), 1e-12);
}

// The contact takes a node's position at the step's start as X + u of the step's start (the
// engine's rewind point) instead of copying x: that holds only while x is X + u bit for bit
// after every step and rewound attempt (steps done in parts: load_halving_test). A probe
// pressed into a ball and dragged sideways (its active set changes from solve to solve).
TEST(ProbeContact, PositionsStayRestPlusDisplacementBitForBit) {
  const double R = 0.05, r = 0.004;
  const TissueModel m = scenario::ball_on_base(R, 4);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver contact(m);
  ContactReport rep;
  int redone = 0;
  Vec3 last_tip(0, 0, R + 0.001);
  for (int k = 0; k < 24; ++k) {
    const Vec3 tip = k < 12 ? Vec3(0, 0, R - 0.0008 * k) : Vec3(0.001 * (k - 11), 0, R - 0.0088);
    Capsule c;
    c.radius = r;
    c.p0 = tip + Vec3(0, 0, r);
    c.p1 = c.p0 + Vec3(0, 0, 0.2);
    c.motion = tip - last_tip;
    last_tip = tip;
    contact.step(m, base, {c}, s, rep);
    ASSERT_FALSE(s.failed) << s.failure;
    if (rep.solves > 1) ++redone;
    const NodeMat x = m.rest.positions + s.u;
    ASSERT_EQ(std::memcmp(x.data(), s.x.data(), sizeof(double) * size_t(x.size())), 0) << "step " << k;
  }
  EXPECT_GT(redone, 0) << "some steps redone with another active set";
}

TEST(ProbeContact, PressFifteenMillimetres) {
  // A ball of radius 5 cm resting on its bottom; a 4 mm probe presses 15 mm into its top.
  const double R = 0.05, r = 0.004;
  TissueDef def = default_tissue(make_icosphere(R, 5));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.04) def.fixed.row(i).setOnes();
  const TissueModel m = scenario::build(def);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSolver contact(m);
  ContactReport rep;
  double last_force = 0.0;
  long total_resolved = 0;  // iterations of the solves before the last, summed
  const double step_mm = 0.5e-3;
  for (int k = 0; k <= 30; ++k) {
    const double tip = R - k * step_mm;
    contact.step(m, base, {vertical_probe(tip, r, k ? -step_mm : 0.0)}, s, rep);
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-4) << "depth " << k * 0.5 << " mm";
    // No free node inside the probe by more than 2 % of its radius.
    EXPECT_LE(rep.max_penetration, 0.02 * r) << "depth " << k * 0.5 << " mm";
    for (int i = 0; i < n; ++i) {
      Vec3 p, nrm;
      if (!contact.active()[i]) {
        EXPECT_GT(capsule_distance(vertical_probe(tip, r), s.x.row(i).transpose(), p, nrm), -0.02 * r);
      }
    }
    // The report's iteration count is every active-set solve's, not only the last one's.
    EXPECT_GE(rep.iterations, s.stats.iterations);
    if (rep.solves > 1) total_resolved += rep.iterations - s.stats.iterations;
    if (k > 0) {
      EXPECT_GT(rep.nodes, 0);
      EXPECT_GT(rep.force.z(), last_force) << "force must rise with depth, depth " << k * 0.5 << " mm";
      last_force = rep.force.z();
    }
  }
  EXPECT_GT(total_resolved, 0);  // the active set re-solved at least once, and it was counted
  // The organ pushes the probe up, and the surface bulges away from the probe.
  EXPECT_GT(last_force, 0.0);
  EXPECT_GT(s.pressure, 0.0);
  double bulge = 0.0;
  for (int i = 0; i < n; ++i)
    if (m.rest.positions(i, 2) < 0.02 && m.rest.positions(i, 2) > -0.02)
      bulge = std::max(bulge, s.u.row(i).dot(m.rest.positions.row(i).normalized()));
  EXPECT_GT(bulge, 1e-5);
}

// The rim of the dent under a wide probe sinks faster than the probe: a node that enters the
// probe there would pull it if held and be released after the first solve. Held only when its
// last motion does not carry it clear, the press is solved once per step almost throughout,
// with the same checks met (nothing inside the probe, the force rising).
TEST(ProbeContact, TheRimUnderAWideProbeIsNotHeldToBeReleased) {
  const double R = 0.05, r = 0.008, step_mm = 0.5e-3;
  const TissueModel m = scenario::ball_on_base(R, 5);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  ContactSettings kinematic;
  kinematic.method = ContactSettings::Method::kinematic;
  ContactSolver contact(m, kinematic);
  ContactReport rep;
  int steps = 0, solved_again = 0;
  double last_force = 0.0;
  for (int k = 0; k <= 30; ++k) {
    contact.step(m, base, {vertical_probe(R - k * step_mm, r, k ? -step_mm : 0.0)}, s, rep);
    ASSERT_FALSE(s.failed);
    EXPECT_LE(rep.max_penetration, 0.02 * r) << "step " << k;
    if (k < 3) continue;  // the first contacts: no motion to go by yet
    ++steps;
    solved_again += rep.solves > 1;
    EXPECT_GT(rep.force.z(), last_force) << "step " << k;
    last_force = rep.force.z();
  }
  std::printf("8 mm probe pressed 15 mm into a 10k ball: %d of %d steps solved more than once\n", solved_again, steps);
  EXPECT_LE(solved_again, steps / 4);  // 18 of 28 when every node found inside is held first
}

// A tool pointing down (-z) with its tip at height `tip_z`: the shape frame's +z (toward the
// tip) is the world's -z; `tip` is how far the tip lies along +z from the shape's origin.
ToolShape pointing_down(ToolShape t, double tip, double tip_z, double step_down) {
  t.pose = Eigen::Translation3d(0, 0, tip_z + tip) * Eigen::AngleAxisd(3.14159265358979323846, Vec3::UnitX());
  t.previous = Eigen::Translation3d(0, 0, step_down) * t.pose;
  return t;
}

struct PressCase {
  const char* name;
  ToolShape shape;
  double tip;  // tip's distance from the shape's origin along its +z
};

std::vector<PressCase> press_cases() {
  std::vector<PressCase> cases;
  ToolShape t;
  t.kind = ToolShape::Kind::capsule;  // radius 6 mm, 40 mm segment
  t.half_size = Vec3(0.006, 0.006, 0.02);
  t.rounding = 0.006;
  cases.push_back({"capsule", t, 0.026});
  t.kind = ToolShape::Kind::cylinder;  // radius 6 mm, 50 mm long, tip edge rounded by 2 mm
  t.half_size = Vec3(0.006, 0.006, 0.025);
  t.rounding = 0.002;
  cases.push_back({"cylinder", t, 0.025});
  t.kind = ToolShape::Kind::box;  // 16 x 12 x 30 mm, sharp
  t.half_size = Vec3(0.008, 0.006, 0.015);
  t.rounding = 0;
  cases.push_back({"box", t, 0.015});
  // The convex hull of a coarse ball stretched along its axis (an egg-like polytope).
  auto hull = std::make_shared<ConvexHull>();
  std::vector<Vec3> pts;
  const SurfaceMesh ico = make_icosphere(0.007, 1);
  for (int i = 0; i < ico.node_count(); ++i) pts.push_back(ico.positions.row(i).transpose().cwiseProduct(Vec3(1, 1, 2)));
  std::string error;
  EXPECT_TRUE(convex_hull(pts, *hull, error)) << error;
  double top = 0;
  for (const Vec3& v : hull->vertices) top = std::max(top, v.z());
  t = ToolShape();
  t.kind = ToolShape::Kind::convex;
  t.hull = hull;
  cases.push_back({"convex", t, top});
  // The same hull rounded by 2 mm (FCL's convex shape has no rounding: its query must be grown
  // by it, or it misses the triangles within the rounding).
  t.rounding = 0.002;
  cases.push_back({"rounded convex", t, top + t.rounding});
  return cases;
}

// A ball of radius R (level-4 icosphere) with its nodes below z = -0.8 R fixed.
TissueModel ball_on_its_bottom(double R) {
  TissueDef def = default_tissue(make_icosphere(R, 4));
  def.fixed = FlagMat::Zero(def.mesh.node_count(), 3);
  for (int i = 0; i < def.mesh.node_count(); ++i)
    if (def.mesh.positions(i, 2) < -0.8 * R) def.fixed.row(i).setOnes();
  return scenario::build(def);
}

TEST(ShapeContact, EveryShapePressesABall) {
  // A ball of radius 5 cm fixed at its bottom; each shape presses 10 mm into its top.
  const double R = 0.05, step_m = 1e-3;
  const TissueModel m = ball_on_its_bottom(R);
  const StepInput base = make_step_input(m);
  for (const PressCase& pc : press_cases()) {
    SimState s = make_sim_state(m), s_fcl = make_sim_state(m);
    ContactSolver contact(m);
    // The same with FCL's shape queries as the broad phase: the same contacts.
    ContactSettings fcl_settings;
    fcl_settings.fcl_shape_queries = true;
    ContactSolver contact_fcl(m, fcl_settings);
    ContactReport rep, rep_fcl;
    double last_force = 0.0;
    const double size = pc.shape.size();
    for (int k = 0; k <= 10; ++k) {
      const ToolShape t = pointing_down(pc.shape, pc.tip, R - k * step_m, k ? step_m : 0.0);
      contact.step(m, base, {t}, s, rep);
      contact_fcl.step(m, base, {t}, s_fcl, rep_fcl);
      const std::string at = std::string(pc.name) + ", depth " + std::to_string(k) + " mm";
      ASSERT_FALSE(s.failed) << at;
      EXPECT_EQ(rep.nodes, rep_fcl.nodes) << at;
      // The same contacts; their prescribed positions agree to round-off, so the two solves
      // (stopped at the solver's relative tolerance, 1e-8) agree far below it.
      EXPECT_LE((s.x - s_fcl.x).cwiseAbs().maxCoeff(), 1e-9 * R) << at;
      EXPECT_LT(std::abs(s.volume_rel_error), 1e-4) << at;
      EXPECT_LE(rep.max_penetration, 0.02 * size) << at;
      // No node inside the instrument by more than 2 % of its size.
      double deepest = 0;
      for (int i = 0; i < m.n; ++i) {
        Vec3 p, nrm;
        deepest = std::max(deepest, -tool_distance(t, s.x.row(i).transpose(), p, nrm));
      }
      EXPECT_LE(deepest, 0.02 * size) << at;
      if (k > 0) {
        EXPECT_GT(rep.nodes, 0) << at;
        EXPECT_GT(rep.force.z(), last_force) << "force must rise with depth: " << at;
        last_force = rep.force.z();
      }
    }
    std::printf("%-8s force at 10 mm: %.4f N\n", pc.name, last_force);
  }
}

TEST(ShapeContact, LooseSolvesKeepTheAnswerAndSaveIterations) {
  // The capsule of EveryShapePressesABall pressed 10 mm into the ball, with the contact
  // iteration's intermediate solves loose (the default) and with every solve to the model's
  // tolerance. Frictionless, the press has one answer: the same iteration with a contact
  // tolerance 25 times tighter is the reference. Both end within a few contact tolerances of
  // it (the tolerance bounds what the last forces would still move a point, along the normal
  // and along the tool), and the loose solves take neither the surface nor the force further
  // from it. With friction 0.2 the two agree within the contact tolerance.
  const double R = 0.05, step_m = 1e-3;
  const TissueModel m = ball_on_its_bottom(R);
  const StepInput base = make_step_input(m);
  const PressCase pc = press_cases().front();
  ASSERT_EQ(pc.shape.kind, ToolShape::Kind::capsule);
  const double tolerance = ContactSettings().constraint_tolerance * pc.shape.size();
  for (const double mu : {0.0, 0.2}) {
    const bool frictionless = mu == 0.0;
    ContactSettings loose, tight, reference;
    loose.friction = tight.friction = reference.friction = mu;
    tight.loose_solves = reference.loose_solves = false;
    reference.constraint_tolerance = tight.constraint_tolerance / 25;
    ContactSolver c_loose(m, loose), c_tight(m, tight), c_ref(m, reference);
    SimState s_loose = make_sim_state(m), s_tight = make_sim_state(m), s_ref = make_sim_state(m);
    ContactReport r_loose, r_tight, r_ref;
    long it_loose = 0, it_tight = 0;
    double apart = 0.0, off_loose = 0.0, off_tight = 0.0;
    for (int k = 0; k <= 10; ++k) {
      const ToolShape t = pointing_down(pc.shape, pc.tip, R - k * step_m, k ? step_m : 0.0);
      c_loose.step(m, base, {t}, s_loose, r_loose);
      c_tight.step(m, base, {t}, s_tight, r_tight);
      if (frictionless) c_ref.step(m, base, {t}, s_ref, r_ref);
      ASSERT_FALSE(s_loose.failed || s_tight.failed || s_ref.failed) << "mu " << mu << ", step " << k;
      EXPECT_TRUE(r_loose.converged && r_tight.converged) << "mu " << mu << ", step " << k;
      it_loose += r_loose.iterations;
      it_tight += r_tight.iterations;
      apart = std::max(apart, (s_loose.x - s_tight.x).cwiseAbs().maxCoeff());
      if (frictionless) {
        off_loose = std::max(off_loose, (s_loose.x - s_ref.x).cwiseAbs().maxCoeff());
        off_tight = std::max(off_tight, (s_tight.x - s_ref.x).cwiseAbs().maxCoeff());
      }
      EXPECT_LT(std::abs(s_loose.volume_rel_error), 1e-9) << "mu " << mu << ", step " << k;
    }
    const double f_loose = r_loose.force.norm(), f_tight = r_tight.force.norm();
    std::printf("friction %.1f: force at 10 mm %.4f N loose, %.4f N tight; %ld against %ld iterations; "
                "at most %.1f um apart\n", mu, f_loose, f_tight, it_loose, it_tight, 1e6 * apart);
    EXPECT_LT(it_loose, 0.8 * it_tight) << "mu " << mu;
    if (frictionless) {
      const double f_ref = r_ref.force.norm();
      std::printf("  reference (contact tolerance / 25): %.4f N; at most %.1f um (loose) and %.1f um (tight) "
                  "from it\n", f_ref, 1e6 * off_loose, 1e6 * off_tight);
      EXPECT_LE(std::abs(f_loose - f_ref), std::abs(f_tight - f_ref) + 1e-3 * f_ref);
      EXPECT_LE(off_loose, off_tight + tolerance);
      EXPECT_LE(off_tight, 5 * tolerance);
    } else {
      EXPECT_LE(apart, tolerance);
    }
  }
}

}  // namespace
}  // namespace vdm
