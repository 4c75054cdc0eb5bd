// The mass-spring baseline: a chain of springs obeys Hooke exactly (also at large stretch),
// a rigid motion costs nothing, and a surface of springs does not keep its volume (a volume
// spring reduces the change).
#include <gtest/gtest.h>

#include <cmath>

#include "engine/mass_spring.hpp"
#include "engine/shapes.hpp"
#include "support/free_input.hpp"

namespace vdm {
namespace {

TEST(MassSpring, ChainStretchesByForceOverStiffness) {
  // 10 springs in series along x, k alternating 50 and 200 N/m, node 0 fixed, 3 N at the end.
  const int n = 11;
  MassSpringDef def;
  def.positions = NodeMat::Zero(n, 3);
  for (int i = 0; i < n; ++i) def.positions(i, 0) = 0.01 * i;
  def.stiffness.resize(n - 1);
  for (int e = 0; e < n - 1; ++e) {
    def.edges.push_back({e, e + 1});
    def.stiffness[e] = e % 2 ? 200.0 : 50.0;
  }
  def.fixed = FlagMat::Ones(n, 3);
  def.fixed.row(n - 1).setZero();
  for (int i = 1; i < n - 1; ++i) def.fixed(i, 0) = 0;  // the chain slides along x
  MassSpringModel m;
  std::string err;
  ASSERT_TRUE(build_mass_spring_model(def, m, err)) << err;
  MassSpringState s = make_mass_spring_state(m);
  StepInput in = test::free_input(n);
  in.force(n - 1, 0) = 3.0;
  step(m, in, s);
  ASSERT_TRUE(s.converged) << s.iterations << " iterations, residual " << s.residual;
  double expected = 0;
  for (int e = 0; e < n - 1; ++e) {
    expected += 3.0 / def.stiffness[e];
    EXPECT_NEAR(s.u(e + 1, 0), expected, 1e-9) << "node " << e + 1;
  }
  EXPECT_NEAR(s.reaction(0, 0), -3.0, 1e-7);  // the support holds the chain back
}

TEST(MassSpring, RigidRotationCostsNothingAndSurfaceLosesVolume) {
  const SurfaceMesh box = make_box(Vec3(0.1, 0.04, 0.04), 5, 2, 2, Vec3(0, 0, 0));
  MassSpringDef def;
  def.positions = box.positions;
  def.triangles = box.triangles;
  MassSpringModel m;
  std::string err;
  ASSERT_TRUE(build_mass_spring_model(def, m, err)) << err;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  NodeMat u(m.n, 3), g;
  for (int i = 0; i < m.n; ++i) u.row(i) = (R * m.rest.row(i).transpose() - m.rest.row(i).transpose()).transpose();
  EXPECT_NEAR(energy(m, u, NodeMat(), &g), 0.0, 1e-18);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-12);
  // Stretch the box 30 % along x by its end faces: without a volume spring the volume changes
  // a lot; with a stiff one much less.
  double change[2] = {0, 0};
  for (int with_volume = 0; with_volume < 2; ++with_volume) {
    def.volume_modulus = with_volume ? 1e5 : 0.0;
    def.fixed = FlagMat::Zero(m.n, 3);
    for (int i = 0; i < m.n; ++i)
      if (m.rest(i, 0) < -0.05 + 1e-9) def.fixed.row(i).setOnes();
    MassSpringModel mv;
    ASSERT_TRUE(build_mass_spring_model(def, mv, err)) << err;
    MassSpringState s = make_mass_spring_state(mv);
    StepInput in = test::free_input(mv.n);
    for (int k = 1; k <= 6; ++k) {
      for (int i = 0; i < mv.n; ++i)
        if (mv.rest(i, 0) > 0.05 - 1e-9) {
          in.prescribed.row(i).setOnes();
          in.prescribed_u.row(i) = Vec3(0.03 * k / 6, 0, 0).transpose();
        }
      step(mv, in, s);
    }
    EXPECT_TRUE(s.converged) << s.iterations << " iterations, residual " << s.residual;
    change[with_volume] = std::abs(s.volume_rel_error);
  }
  EXPECT_GT(change[0], 0.05) << "surface springs alone do not keep the volume";
  EXPECT_LT(change[1], 0.5 * change[0]);
}

}  // namespace
}  // namespace vdm
