#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include "engine/membrane_strain.hpp"
#include "engine/stress.hpp"
#include "support/simd_paths.hpp"
#include "support/scenarios.hpp"

using namespace vdm;
using namespace vdm::scenario;

namespace {

// Eqs (5)-(6) written out plainly, entry by entry (each axis's neighbour sum in the
// pattern's order): what compute_strain_stress() must give bit for bit.
void plain_strain_stress(const TissueModel& m, const SimState& s, NodeMat& strain, NodeMat& stress) {
  const NodeMat& A = s.area_vectors;
  const int* outer = m.pattern.matrix.outerIndexPtr();
  const int* inner = m.pattern.matrix.innerIndexPtr();
  strain.resize(m.n, 3);
  stress.resize(m.n, 3);
  for (int i = 0; i < m.n; ++i) {
    const double inv_v = 1.0 / s.node_volumes[i];
    for (int d = 0; d < 3; ++d) {
      double sum = 0.0;
      if (m.connectivity_modulus != 0.0)
        for (int k = outer[i]; k < outer[i + 1]; ++k) sum += A(i, d) * s.u(i, d) - A(inner[k], d) * s.u(inner[k], d);
      const double tension = m.connectivity_modulus * sum * inv_v;
      if (m.infinite(i, d)) {
        strain(i, d) = 0.0;
        const double tiny = 1e-9 * A.row(i).norm();
        stress(i, d) = (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0) + tension;
      } else {
        strain(i, d) = A(i, d) * s.u(i, d) * inv_v;
        stress(i, d) = m.bulk(i, d) * strain(i, d) + tension;
      }
    }
  }
}

// The cube's top pressed 4, 8, 12 mm in three steps.
SimState pressed_three_steps(const TissueModel& m, double L) {
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 3 && !s.failed; ++k) {
    press_top(m, L, -0.004 * k, in);
    step(m, in, s);
  }
  return s;
}

bool same_bits(const NodeMat& a, const NodeMat& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * size_t(a.size())) == 0;
}

}  // namespace

// A pressed cube with an infinite B along x on some nodes (the constraint's reaction as
// their bulk stress): the step's strain and stress to round-off; compute_strain_stress() on
// the state bit for bit, with and without the capsule term.
TEST(StrainStress, EqualsThePlainFormulasBitForBit) {
  const double L = 0.1;
  TissueDef def = cube_on_table(L, 4);
  def.capsule = CapsuleForm::paper;  // eq (6) as the paper writes it
  const int n = def.mesh.node_count();
  def.bulk_modulus = NodeMat::Constant(n, 3, 20000.0);
  for (int i = 0; i < n; i += 3) def.bulk_modulus(i, 0) = std::numeric_limits<double>::infinity();
  def.bulk_modulus(1, 1) = def.bulk_modulus(1, 2) = std::numeric_limits<double>::infinity();
  TissueModel m = build(def);
  ASSERT_FALSE(m.infinite_nodes.empty());
  SimState s = pressed_three_steps(m, L);
  ASSERT_FALSE(s.failed);
  ASSERT_GT(s.reaction.cwiseAbs().maxCoeff(), 0.0);
  NodeMat strain, stress;
  plain_strain_stress(m, s, strain, stress);
  // The step's own (compute_step_results: the neighbour sums in another order) to round-off.
  EXPECT_LE((strain - s.strain).cwiseAbs().maxCoeff(), 1e-13 * strain.cwiseAbs().maxCoeff());
  EXPECT_LE((stress - s.stress).cwiseAbs().maxCoeff(), 1e-12 * stress.cwiseAbs().maxCoeff());
  // Called alone on the state, with its own scratch, with and without the capsule term.
  for (const double bc : {2000.0, 0.0}) {
    m.connectivity_modulus = bc;
    plain_strain_stress(m, s, strain, stress);
    s.strain.setConstant(7.0);
    s.stress.setConstant(7.0);
    std::vector<double> scratch(4 * size_t(m.n), -1.0);
    compute_strain_stress(m, s, scratch.data());
    EXPECT_TRUE(same_bits(strain, s.strain)) << "B_c " << bc;
    EXPECT_TRUE(same_bits(stress, s.stress)) << "B_c " << bc;
  }
}

// The membrane's Green strain at each triangle, written another way: from the metric tensors
// in the edge basis, E_edge = ½ (dᵀd − Dᵀ D), pushed to world coordinates by the rest edge
// matrix's pseudo-inverse, E3 = D G⁻¹ E_edge G⁻¹ Dᵀ (G = Dᵀ D); averaged to nodes by area.
NodeMat metric_strain(const TissueModel& m, const NodeMat& x) {
  NodeMat acc = NodeMat::Zero(m.n, 3);
  Vec weight = Vec::Zero(m.n);
  for (int t = 0; t < m.rest.triangle_count(); ++t) {
    const int a = m.rest.triangles(t, 0), b = m.rest.triangles(t, 1), c = m.rest.triangles(t, 2);
    Eigen::Matrix<double, 3, 2> D, d;
    D << (m.rest.positions.row(b) - m.rest.positions.row(a)).transpose(),
        (m.rest.positions.row(c) - m.rest.positions.row(a)).transpose();
    d << (x.row(b) - x.row(a)).transpose(), (x.row(c) - x.row(a)).transpose();
    const Eigen::Matrix2d G = D.transpose() * D, E = 0.5 * (d.transpose() * d - G);
    const Eigen::Matrix<double, 3, 2> P = D * G.inverse();
    const Eigen::Matrix3d E3 = P * E * P.transpose();
    const double area = 0.5 * D.col(0).cross(D.col(1)).norm();
    for (const int i : {a, b, c}) {
      acc.row(i) += area * E3.diagonal().transpose();
      weight[i] += area;
    }
  }
  for (int i = 0; i < m.n; ++i) acc.row(i) /= weight[i];
  return acc;
}

// The membrane capsule's stress: B eps plus B_ij times the skin's Green strain (docs/model.md);
// the step's and compute_strain_stress()'s agree with it written another way.
TEST(StrainStress, MembraneStressIsBulkPlusTheSkinsGreenStrain) {
  const double L = 0.1;
  TissueDef def = cube_on_table(L, 4);
  def.capsule = CapsuleForm::membrane;
  const TissueModel m = build(def);
  SimState s = pressed_three_steps(m, L);
  ASSERT_FALSE(s.failed);
  const NodeMat E = metric_strain(m, s.x);
  NodeMat want(m.n, 3);
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) want(i, d) = m.bulk(i, d) * s.strain(i, d) + m.connectivity_modulus * E(i, d);
  const double scale = want.cwiseAbs().maxCoeff();
  EXPECT_LE((want - s.stress).cwiseAbs().maxCoeff(), 1e-9 * scale);
  std::vector<double> scratch(4 * size_t(m.n), -1.0);
  SimState again = make_sim_state(m);
  again.u = s.u;
  again.x = s.x;
  again.area_vectors = s.area_vectors;
  again.node_volumes = s.node_volumes;
  again.reaction = s.reaction;
  compute_strain_stress(m, again, scratch.data());
  EXPECT_LE((want - again.stress).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_GT(E.cwiseAbs().maxCoeff(), 1e-3) << "the press stretches the skin";
}

// Analytic cases of the skin's strain: a rigid rotation strains nothing (the measure is
// rotation invariant); a uniform stretch by lambda along x gives E_xx = (lambda² − 1) / 2 on the
// faces that contain x, and 0 along y and z where nothing stretches.
TEST(StrainStress, MembraneStrainOfARotationAndOfAStretch) {
  TissueDef def = default_tissue(make_box(Vec3(0.1, 0.1, 0.1), 4, 4, 4));
  const TissueModel m = build(def);
  std::vector<double> scratch(4 * size_t(m.n));
  NodeMat E(m.n, 3);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const NodeMat rotated = (m.rest.positions * R.transpose()).eval();
  membrane_axis_strain(m, rotated - m.rest.positions, E, scratch.data());
  EXPECT_LT(E.cwiseAbs().maxCoeff(), 1e-13);
  const double lambda = 1.3;
  NodeMat stretched = m.rest.positions;
  stretched.col(0) *= lambda;
  membrane_axis_strain(m, stretched - m.rest.positions, E, scratch.data());
  for (int i = 0; i < m.n; ++i) {
    // a node inside the top face (z = 0.05, not on its rim): only its own face's triangles
    if (std::abs(m.rest.positions(i, 2) - 0.05) < 1e-12 && std::abs(m.rest.positions(i, 0)) < 0.049 &&
        std::abs(m.rest.positions(i, 1)) < 0.049) {
      EXPECT_NEAR(E(i, 0), 0.5 * (lambda * lambda - 1), 1e-12);
      EXPECT_NEAR(E(i, 1), 0.0, 1e-12);
      EXPECT_NEAR(E(i, 2), 0.0, 1e-12);
    }
  }
}

// The strain against the same Green strain written another way, per triangle from the metric
// tensors of its rest and deformed edges (E = ½ (G_def − G_rest) in the edges' coordinates,
// pushed to the world by the rest edges' pseudo-inverse), averaged to the nodes by rest area
// in the test itself: on a sphere whose nodes move at random by up to 4 mm (about a tenth of
// an edge) on each axis.
TEST(StrainStress, MembraneStrainMatchesTheMetricTensorForm) {
  TissueDef def = default_tissue(make_uv_sphere(0.05, 8, 9));
  const TissueModel m = build(def);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  NodeMat u(m.n, 3);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = jitter(rng);
  NodeMat want = NodeMat::Zero(m.n, 3);
  Vec area = Vec::Zero(m.n);
  for (int t = 0; t < m.rest.triangle_count(); ++t) {
    const int a = m.rest.triangles(t, 0), b = m.rest.triangles(t, 1), c = m.rest.triangles(t, 2);
    Eigen::Matrix<double, 3, 2> rest, def_edges;
    rest.col(0) = (m.rest.positions.row(b) - m.rest.positions.row(a)).transpose();
    rest.col(1) = (m.rest.positions.row(c) - m.rest.positions.row(a)).transpose();
    def_edges.col(0) = rest.col(0) + (u.row(b) - u.row(a)).transpose();
    def_edges.col(1) = rest.col(1) + (u.row(c) - u.row(a)).transpose();
    const Eigen::Matrix2d G_rest = rest.transpose() * rest, G_def = def_edges.transpose() * def_edges;
    const Eigen::Matrix<double, 2, 3> pinv = G_rest.inverse() * rest.transpose();
    const Eigen::Matrix3d E3 = pinv.transpose() * (0.5 * (G_def - G_rest)) * pinv;
    const double A = 0.5 * rest.col(0).cross(rest.col(1)).norm();
    for (const int i : {a, b, c}) {
      for (int d = 0; d < 3; ++d) want(i, d) += A * E3(d, d);
      area[i] += A;
    }
  }
  for (int i = 0; i < m.n; ++i) want.row(i) /= area[i];
  std::vector<double> scratch(4 * size_t(m.n));
  NodeMat E(m.n, 3);
  membrane_axis_strain(m, u, E, scratch.data());
  EXPECT_GT(want.cwiseAbs().maxCoeff(), 1e-2);
  EXPECT_LE((E - want).cwiseAbs().maxCoeff(), 1e-12 * want.cwiseAbs().maxCoeff() + 1e-15);
}

// The strain's AVX2 path (four triangles per vector) gives the SSE2 path's bits, on a mesh whose
// triangle count is not a multiple of four (a partial last block) under a random displacement.
TEST(StrainStress, MembraneStrainSameBitsWithAndWithoutAvx2) {
  TissueDef def = default_tissue(make_uv_sphere(0.05, 6, 7));
  const TissueModel m = build(def);
  ASSERT_NE(m.rest.triangle_count() % 4, 0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  NodeMat u(m.n, 3);
  for (Eigen::Index k = 0; k < u.size(); ++k) u.data()[k] = jitter(rng);
  std::vector<double> scratch(4 * size_t(m.n));
  NodeMat E[2] = {NodeMat(m.n, 3), NodeMat(m.n, 3)};
  simd_test::sse2_then_avx2([&](bool avx2) { membrane_axis_strain(m, u, E[avx2], scratch.data()); });
  EXPECT_GT(E[0].cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_EQ(0, std::memcmp(E[0].data(), E[1].data(), sizeof(double) * size_t(E[0].size())));
}
