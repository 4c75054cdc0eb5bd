// The elastic core with inertia (engine/core, implicit Euler on the lattice's lumped mass):
// a free organ coasts and its damping decays as the analytic answers say, momentum is kept
// while it deforms, a cantilever's period follows from its own static sag as a beam's does,
// and a step solved again after rewind() gives the same answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/core/elastic_core.hpp"
#include "engine/shapes.hpp"
#include "support/cantilever.hpp"
#include "support/free_input.hpp"

namespace vdm::core {
namespace {

constexpr double kInertiaDensity = 1000;

CoreModel build_dynamic_core(const SurfaceMesh& s, double young, double h, double dt, double damping,
                             const FlagMat& fixed = FlagMat(), bool gravity = false) {
  CoreDef def;
  def.surface = s;
  def.young_modulus = young;
  def.cell_size = h;
  def.fixed = fixed;
  def.density = kInertiaDensity;
  def.use_gravity = gravity;
  def.use_inertia = true;
  def.damping = damping;
  def.dt = dt;
  CoreModel m;
  std::string error;
  EXPECT_TRUE(build_core_model(def, m, error)) << error;
  return m;
}

Vec3 lattice_momentum(const CoreModel& m, const CoreState& s) {
  return (s.velocity.array().colwise() * m.mass.array()).colwise().sum().transpose();
}

TEST(CoreInertia, LatticeMassIsTheOrgansMass) {
  const SurfaceMesh sphere = make_icosphere(0.04, 3);
  const CoreModel m = build_dynamic_core(sphere, 3000, 0.008, 0.01, 0);
  EXPECT_NEAR(m.mass.sum() / (kInertiaDensity * m.rest_volume), 1.0, 0.03);
}

TEST(CoreInertia, FreeOrganCoastsAndItsDampingDecaysAsImplicitEuler) {
  // No force, nothing held, every lattice node at velocity v0: the organ translates rigidly,
  // by v0 dt per step undamped; with mass-proportional damping c implicit Euler gives
  // v_{n+1} = v_n / (1 + c dt).
  const SurfaceMesh sphere = make_icosphere(0.04, 3);
  const double dt = 0.01;
  const Vec3 v0(0.2, -0.1, 0.05);
  for (const double c : {0.0, 5.0}) {
    const CoreModel m = build_dynamic_core(sphere, 3000, 0.01, dt, c);
    CoreState s = make_core_state(m);
    s.velocity.rowwise() = v0.transpose();
    const StepInput in = test::free_input(m.ns);
    Vec3 travelled = Vec3::Zero(), speed = v0;
    for (int n = 0; n < 10; ++n) {
      step(m, in, s);
      ASSERT_TRUE(s.stats.converged);
      speed /= 1 + c * dt;
      travelled += dt * speed;
      for (int j = 0; j < m.ng; ++j) {
        ASSERT_LT((s.velocity.row(j).transpose() - speed).norm(), 1e-6 * v0.norm()) << "c " << c << " step " << n;
        ASSERT_LT((s.v.row(j).transpose() - travelled).norm(), 1e-6 * travelled.norm());
      }
      for (int i = 0; i < m.ns; ++i) ASSERT_LT((s.u.row(i).transpose() - travelled).norm(), 1e-6 * travelled.norm());
      EXPECT_LT(std::abs(s.volume_rel_error), 1e-12);
    }
  }
}

TEST(CoreInertia, DeformingFreeOrganKeepsItsMomentum) {
  // A free box set spinning and squeezed (a velocity field with a rotation and a strain):
  // the core's forces and the fluid's pressure are internal, so implicit Euler keeps the
  // lattice's momentum while the organ deforms; the volume stays.
  const SurfaceMesh box = make_box(Vec3(0.06, 0.04, 0.03), 12, 8, 6);
  const CoreModel m = build_dynamic_core(box, 3000, 0.006, 0.005, 0);
  CoreState s = make_core_state(m);
  for (int j = 0; j < m.ng; ++j) {
    const Vec3 p = m.lattice.row(j).transpose();
    s.velocity.row(j) = (Vec3(0.3, 0.1, 0.0) + Vec3(0, 0, 4.0).cross(p) + Vec3(2.0 * p.x(), -3.0 * p.y(), p.z())).transpose();
  }
  const Vec3 p0 = lattice_momentum(m, s);
  const StepInput in = test::free_input(m.ns);
  double largest_strain_motion = 0;
  for (int n = 0; n < 20; ++n) {
    step(m, in, s);
    ASSERT_TRUE(s.stats.converged);
    const Vec3 p = lattice_momentum(m, s);
    EXPECT_LT((p - p0).norm(), 1e-6 * p0.norm()) << "step " << n;
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-12);
    // It did deform: the lattice is not a rigid motion of itself.
    const Vec3 mean = s.v.colwise().mean().transpose();
    largest_strain_motion = std::max(largest_strain_motion, (s.v.rowwise() - mean.transpose()).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest_strain_motion, 1e-3);
}

TEST(CoreInertia, CantileverPeriodFollowsFromItsStaticSag) {
  // A uniform cantilever's first bending mode and its static tip deflection under its own
  // weight are tied for any stiffness: omega^2 = 12.36 EI / (rho A L^4) and
  // delta = rho A g L^4 / (8 EI), so omega^2 delta / g = 1.545 (Euler-Bernoulli). The core's
  // own static sag then predicts the period with which it swings when its weight is switched
  // on at rest; the swing is measured between the first two maxima of the tip's deflection.
  const double L = 0.1, a = 0.01, young = 5e6, h = 0.0025, dt = 0.0015;
  const SurfaceMesh beam = test::cantilever_surface(L, a, 40, 4);
  const FlagMat fixed = test::cantilever_root(beam);
  // The static sag: the same core with a very long step (its inertia 1e-12 of its stiffness).
  const CoreModel settled = build_dynamic_core(beam, young, h, 1e3, 0, fixed, true);
  CoreState ss = make_core_state(settled);
  const StepInput in = test::free_input(settled.ns);
  step(settled, in, ss);
  ASSERT_TRUE(ss.stats.converged);
  const double sag = -test::cantilever_tip_z(beam, ss.u, L);
  ASSERT_GT(sag, 0.005 * L);
  ASSERT_LT(sag, 0.1 * L);
  const double period_expected = 2 * M_PI / std::sqrt(1.545 * 9.81 / sag);

  const CoreModel m = build_dynamic_core(beam, young, h, dt, 0, fixed, true);
  CoreState s = make_core_state(m);
  std::vector<double> deflection;
  for (int n = 0; n < static_cast<int>(2.5 * period_expected / dt); ++n) {
    step(m, in, s);
    ASSERT_TRUE(s.stats.converged);
    deflection.push_back(-test::cantilever_tip_z(beam, s.u, L));
  }
  // It moves with its own dynamics: it swings past the static sag (implicit Euler damps the
  // swing, so less than the undamped 2x) and back.
  std::vector<double> peak_time;
  for (size_t n = 1; n + 1 < deflection.size(); ++n)
    if (deflection[n] > deflection[n - 1] && deflection[n] >= deflection[n + 1]) {
      // The parabola through the three samples puts the peak between them.
      const double d0 = deflection[n - 1], d1 = deflection[n], d2 = deflection[n + 1];
      const double shift = 0.5 * (d0 - d2) / (d0 - 2 * d1 + d2);
      peak_time.push_back((static_cast<double>(n) + 1 + shift) * dt);
    }
  ASSERT_GE(peak_time.size(), 2u);
  const double first_peak = *std::max_element(deflection.begin(), deflection.end());
  EXPECT_GT(first_peak, 1.3 * sag);
  EXPECT_LT(first_peak, 2.0 * sag);
  const double period = peak_time[1] - peak_time[0];
  EXPECT_NEAR(period / period_expected, 1.0, 0.1) << "period " << period << " s, from the sag " << period_expected << " s";
}

TEST(CoreInertia, StepSolvedAgainAfterRewindStartsWhereItStarted) {
  // A step solved twice (contact does so) is the same step: the second starts from the first
  // one's start, not from its answer.
  const SurfaceMesh sphere = make_icosphere(0.04, 3);
  const CoreModel m = build_dynamic_core(sphere, 3000, 0.01, 0.02, 1.0);
  CoreState s = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  in.force.col(2).setConstant(-0.01);
  step(m, in, s);
  step(m, in, s);
  const NodeMat u_once = s.u, velocity_once = s.velocity;
  rewind(s);
  step(m, in, s);
  EXPECT_LT((s.u - u_once).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((s.velocity - velocity_once).cwiseAbs().maxCoeff(), 1e-7);
  // Not rewound, the next step goes on from there.
  step(m, in, s);
  EXPECT_GT((s.u - u_once).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace vdm::core
