#include <gtest/gtest.h>
#include <cmath>
#include <cstring>
#include <limits>
#include "engine/stress.hpp"
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
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 3; ++k) {
    press_top(m, L, -0.004 * k, in);
    step(m, in, s);
  }
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
    std::vector<double> scratch(3 * size_t(m.n), -1.0);
    compute_strain_stress(m, s, scratch.data());
    EXPECT_TRUE(same_bits(strain, s.strain)) << "B_c " << bc;
    EXPECT_TRUE(same_bits(stress, s.stress)) << "B_c " << bc;
  }
}

// The membrane capsule's stress: B eps plus the membrane's force per patch area,
// sum_j w_ij (u_i - u_j) / |A_i| (docs/model.md). The step's own to round-off (it sums
// lap_i u_i - sum_j w_ij u_j), compute_strain_stress() bit for bit.
TEST(StrainStress, MembraneCapsuleEqualsThePlainFormula) {
  const double L = 0.1;
  TissueDef def = cube_on_table(L, 4);
  def.capsule = CapsuleForm::membrane;
  const int n = def.mesh.node_count();
  def.bulk_modulus = NodeMat::Constant(n, 3, 20000.0);
  for (int i = 0; i < n; i += 3) def.bulk_modulus(i, 0) = std::numeric_limits<double>::infinity();
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 3; ++k) {
    press_top(m, L, -0.004 * k, in);
    step(m, in, s);
  }
  ASSERT_FALSE(s.failed);
  NodeMat strain(m.n, 3), stress(m.n, 3);
  const NodeMat& A = s.area_vectors;
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) {
      double force = 0.0;
      for (int k = m.neighbours.begin[i]; k < m.neighbours.begin[i + 1]; ++k) {
        const auto e = m.neighbours.entries[size_t(k)];
        force += m.capsule_weight[e.edge] * (s.u(i, d) - s.u(e.node, d));
      }
      strain(i, d) = m.infinite(i, d) ? 0.0 : A(i, d) * s.u(i, d) / s.node_volumes[i];
      const double tiny = 1e-9 * A.row(i).norm();
      const double bulk = m.infinite(i, d) ? (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0)
                                           : m.bulk(i, d) * strain(i, d);
      stress(i, d) = (m.infinite(i, d) ? force / A.row(i).norm() + bulk : bulk + force / A.row(i).norm());
    }
  EXPECT_LE((strain - s.strain).cwiseAbs().maxCoeff(), 1e-13 * strain.cwiseAbs().maxCoeff());
  EXPECT_LE((stress - s.stress).cwiseAbs().maxCoeff(), 1e-9 * stress.cwiseAbs().maxCoeff());
  std::vector<double> scratch(3 * size_t(m.n), -1.0);
  SimState again = make_sim_state(m);
  again.u = s.u;
  again.area_vectors = s.area_vectors;
  again.node_volumes = s.node_volumes;
  again.reaction = s.reaction;
  compute_strain_stress(m, again, scratch.data());
  EXPECT_LE((stress - again.stress).cwiseAbs().maxCoeff(), 1e-12 * stress.cwiseAbs().maxCoeff());
  EXPECT_LE((strain - again.strain).cwiseAbs().maxCoeff(), 1e-13 * strain.cwiseAbs().maxCoeff());
  // The capsule's share is not nothing: without it the stress differs.
  double capsule_share = 0.0, largest = 0.0;
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d)
      if (!m.infinite(i, d)) {
        capsule_share = std::max(capsule_share, std::abs(stress(i, d) - m.bulk(i, d) * strain(i, d)));
        largest = std::max(largest, std::abs(stress(i, d)));
      }
  EXPECT_GT(capsule_share, 0.01 * largest);
}
