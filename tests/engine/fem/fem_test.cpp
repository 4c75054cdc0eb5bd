// The FEM reference against analytic elasticity: structured tet boxes, rigid motions cost
// nothing (corotation), uniaxial stretch gives stress E strain and lateral contraction nu,
// a slender cantilever's tip deflection matches F L^3 / (3 E I), and volumetric locking.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/fem/fem_state.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"

namespace vdm::fem {
namespace {

FemModel build(const FemDef& def) {
  FemModel m;
  std::string err;
  EXPECT_TRUE(build_fem_model(def, m, err)) << err;
  return m;
}

StepInput surface_input(const FemModel& m) {
  StepInput in;
  in.force = NodeMat::Zero(m.ns, 3);
  in.prescribed = FlagMat::Zero(m.ns, 3);
  in.prescribed_u = NodeMat::Zero(m.ns, 3);
  return in;
}

TEST(TetMesh, BoxTetsFillTheBoxAndTheirBoundaryIsMakeBox) {
  const Vec3 size(0.3, 0.1, 0.2), c(0.05, -0.02, 0.3);
  TetMesh t = make_box_tets(size, 3, 2, 4, c);
  const SurfaceMesh s = make_box(size, 3, 2, 4, c);
  ASSERT_EQ(t.surface_nodes, s.node_count());
  EXPECT_EQ((t.positions.topRows(t.surface_nodes) - s.positions).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(t.tet_count(), 3 * 2 * 4 * 24);
  double v = 0;
  for (int k = 0; k < t.tet_count(); ++k) {
    const double vk = tet_volume(t.positions.row(t.tets(k, 0)), t.positions.row(t.tets(k, 1)),
                                 t.positions.row(t.tets(k, 2)), t.positions.row(t.tets(k, 3)));
    EXPECT_GT(vk, 0);
    v += vk;
  }
  EXPECT_NEAR(v, size.prod(), 1e-12 * size.prod());
  // The boundary found from the tets is the box surface, outward.
  TetMesh checked = t;
  checked.surface.triangles.resize(0, 3);
  std::string err;
  ASSERT_TRUE(check_tet_mesh(checked, err)) << err;
  EXPECT_EQ(checked.surface.triangle_count(), s.triangle_count());
  EXPECT_NEAR(enclosed_volume(checked.surface.positions, checked.surface.triangles, c), size.prod(), 1e-12);
}

TEST(Fem, RigidRotationCostsNothing) {
  FemDef def;
  def.mesh = make_box_tets(Vec3(0.1, 0.04, 0.06), 3, 2, 2);
  def.young_modulus = 5000;
  def.poisson_ratio = 0.49;
  const FemModel m = build(def);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  NodeMat u(m.n, 3);
  for (int i = 0; i < m.n; ++i) {
    const Vec3 X = m.mesh.positions.row(i);
    u.row(i) = (R * X + Vec3(0.01, -0.02, 0.03) - X).transpose();
  }
  NodeMat g;
  EXPECT_NEAR(energy(m, u, NodeMat(), &g), 0.0, 1e-14);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-10);
  // A step that rotates the whole surface by 90 degrees: no force, volume kept, interior rigid.
  FemState s = make_fem_state(m);
  StepInput in = surface_input(m);
  in.prescribed.setOnes();
  const Eigen::Matrix3d R90 = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  for (int k = 1; k <= 6; ++k) {
    const Eigen::Matrix3d Rk = Eigen::AngleAxisd(k * M_PI / 12, Vec3::UnitZ()).toRotationMatrix();
    for (int i = 0; i < m.ns; ++i) {
      const Vec3 X = m.mesh.positions.row(i);
      in.prescribed_u.row(i) = (Rk * X - X).transpose();
    }
    step(m, in, s);
    ASSERT_TRUE(s.stats.converged);
  }
  EXPECT_LT(s.reaction.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(s.volume_rel_error, 0.0, 1e-12);
  for (int i = 0; i < m.n; ++i) {
    const Vec3 X = m.mesh.positions.row(i);
    EXPECT_LT((X + s.u.row(i).transpose() - R90 * X).norm(), 1e-9) << "node " << i;
  }
}

// Unit cube [0, L]^3 on rollers (x = 0, y = 0, z = 0 faces hold their normal component),
// face x = L pulled to u_x = strain L: the exact answer is homogeneous.
struct Uniaxial {
  double force = 0;        // total reaction on the pulled face (N)
  double lateral = 0;      // lateral strain at the far corner
  double volume_rel = 0;
};
Uniaxial stretch(double E, double nu, double strain, bool nodal) {
  const double L = 0.05;
  FemDef def;
  def.mesh = make_box_tets(Vec3(L, L, L), 3, 3, 3, Vec3(L / 2, L / 2, L / 2));
  def.young_modulus = E;
  def.poisson_ratio = nu;
  def.settings.nodal_volumetric = nodal;
  const int ns = def.mesh.surface_nodes;
  def.fixed = FlagMat::Zero(ns, 3);
  int corner = -1;
  for (int i = 0; i < ns; ++i)
    for (int d = 0; d < 3; ++d) {
      if (def.mesh.positions(i, d) < 1e-12) def.fixed(i, d) = 1;
      if ((def.mesh.positions.row(i).array() > L - 1e-12).all()) corner = i;
    }
  const FemModel m = build(def);
  FemState s = make_fem_state(m);
  StepInput in = surface_input(m);
  for (int k = 1; k <= 4; ++k) {
    for (int i = 0; i < m.ns; ++i)
      if (m.mesh.positions(i, 0) > L - 1e-12) {
        in.prescribed(i, 0) = 1;
        in.prescribed_u(i, 0) = strain * L * k / 4;
      }
    step(m, in, s);
    EXPECT_TRUE(s.stats.converged);
  }
  Uniaxial r;
  for (int i = 0; i < m.ns; ++i)
    if (m.mesh.positions(i, 0) > L - 1e-12) r.force += s.reaction(i, 0);
  r.force /= L * L;
  r.lateral = s.u(corner, 1) / L;
  r.volume_rel = s.volume_rel_error;
  return r;
}

TEST(Fem, UniaxialStretchGivesYoungsModulusAndPoissonsRatio) {
  for (double nu : {0.0, 0.3, 0.45, 0.49})
    for (bool nodal : {true, false})
      for (double strain : {1e-4, 0.2}) {
        const double E = 3000;
        const Uniaxial r = stretch(E, nu, strain, nodal);
        // Corotational linear: Biot stress = E x engineering strain, exactly, at any stretch.
        EXPECT_NEAR(r.force, E * strain, 1e-6 * E * strain) << "nu " << nu << " strain " << strain;
        EXPECT_NEAR(r.lateral, -nu * strain, 1e-6 * strain) << "nu " << nu << " strain " << strain;
        // Volume: (1 + e)(1 - nu e)^2 - 1.
        EXPECT_NEAR(r.volume_rel, (1 + strain) * (1 - nu * strain) * (1 - nu * strain) - 1, 1e-9);
      }
}

// Cantilever along y (L = 10 h), clamped at y = 0, a small tip load F along -x spread over the
// tip face; returns the mean tip deflection and the Euler-Bernoulli value F L^3 / (3 E I).
double cantilever_tip(double nu, bool nodal, int across, int along, double* theory) {
  const double h = 0.01, L = 10 * h, E = 1e5, F = 1e-6;
  FemDef def;
  def.mesh = make_box_tets(Vec3(h, L, h), across, along, across, Vec3(0, L / 2, 0));
  def.young_modulus = E;
  def.poisson_ratio = nu;
  def.settings.nodal_volumetric = nodal;
  def.settings.direct_max_dofs = 1 << 30;  // LDL^T: a slender beam is hard for CG
  const int ns = def.mesh.surface_nodes;
  def.fixed = FlagMat::Zero(ns, 3);
  for (int i = 0; i < ns; ++i)
    if (def.mesh.positions(i, 1) < 1e-12) def.fixed.row(i).setOnes();
  const FemModel m = build(def);
  FemState s = make_fem_state(m);
  StepInput in = surface_input(m);
  std::vector<int> tip;
  for (int i = 0; i < ns; ++i)
    if (m.mesh.positions(i, 1) > L - 1e-12) tip.push_back(i);
  for (int i : tip) in.force(i, 0) = -F / double(tip.size());
  step(m, in, s);
  EXPECT_TRUE(s.stats.converged);
  double u = 0;
  for (int i : tip) u -= s.u(i, 0) / double(tip.size());
  *theory = F * L * L * L / (3 * E * h * h * h * h / 12);
  return u;
}

#ifdef VDMSIM_SANITIZED
#define SKIP_FINE_MESH() GTEST_SKIP() << "52k-tet beam: too slow under sanitizers, run in the plain build"
#else
#define SKIP_FINE_MESH() (void)0
#endif

TEST(Fem, SlenderCantileverTipDeflectionMatchesBeamTheory) {
  SKIP_FINE_MESH();
  // 10:1 beam, 6 x 6 x 60 cells (52k tets), nu = 0.3: within 3 % of F L^3 / 3EI (shear
  // deformation adds about 0.8 % to that; linear tets are a little stiff in bending).
  double theory = 0;
  const double u = cantilever_tip(0.3, false, 6, 60, &theory);
  EXPECT_NEAR(u / theory, 1.0, 0.03) << "tip " << u << " m, theory " << theory << " m";
  EXPECT_LT(u / theory, 1.01);  // the discretisation is stiffer, never softer
}

TEST(Fem, NearlyIncompressibleCantileverIsWithinFivePercent) {
  SKIP_FINE_MESH();
  // nu = 0.49: the same mesh is 4 % stiff (measured 0.962 of theory), with theta per tet and
  // with the nodal average alike: the 24-tet split of each cell does not lock.
  double theory = 0;
  const double u = cantilever_tip(0.49, false, 6, 60, &theory);
  EXPECT_NEAR(u / theory, 1.0, 0.05) << "tip " << u << " m, theory " << theory << " m";
}

TEST(Fem, CoarseCantileverConvergesFromBelowAndNodalAverageIsSofter) {
  double theory = 0;
  const double c2 = cantilever_tip(0.45, false, 2, 20, &theory);
  const double c3 = cantilever_tip(0.45, false, 3, 30, &theory);
  const double n3 = cantilever_tip(0.45, true, 3, 30, &theory);
  EXPECT_LT(c2, c3);
  EXPECT_LT(c3, theory * 1.01);
  EXPECT_GT(n3, c3);  // fewer volumetric constraints: less locking
  EXPECT_LT(n3, theory * 1.01);
}

}  // namespace
}  // namespace vdm::fem
