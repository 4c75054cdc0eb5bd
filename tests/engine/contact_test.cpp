// Kinematic probe contact against analytic geometry and physics.
#include <gtest/gtest.h>

#include "engine/contact.hpp"
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
    if (k > 0) {
      EXPECT_GT(rep.nodes, 0);
      EXPECT_GT(rep.force.z(), last_force) << "force must rise with depth, depth " << k * 0.5 << " mm";
      last_force = rep.force.z();
    }
  }
  // The organ pushes the probe up, and the surface bulges away from the probe.
  EXPECT_GT(last_force, 0.0);
  EXPECT_GT(s.pressure, 0.0);
  double bulge = 0.0;
  for (int i = 0; i < n; ++i)
    if (m.rest.positions(i, 2) < 0.02 && m.rest.positions(i, 2) > -0.02)
      bulge = std::max(bulge, s.u.row(i).dot(m.rest.positions.row(i).normalized()));
  EXPECT_GT(bulge, 1e-5);
}

}  // namespace
}  // namespace vdm
