#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "engine/mesh_topology.hpp"
#include "engine/shapes.hpp"
#include "engine/sparse_ldlt.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

TEST(SparseLdlt, SolvesALaplacianPlusDiagonalLikeADenseFactorisation) {
  const SurfaceMesh s = make_icosphere(1.0, 2);
  const auto edges = unique_edges(s.triangles);
  StiffnessPattern p = build_stiffness_pattern(s.node_count(), edges);
  SpMat K = p.matrix;
  std::srand(3);
  for (size_t e = 0; e < edges.size(); ++e) {
    const double w = 0.5 + double(std::rand()) / RAND_MAX;
    K.valuePtr()[p.edge_slot[e][0]] -= w;
    K.valuePtr()[p.edge_slot[e][1]] -= w;
    K.valuePtr()[p.diagonal[edges[e][0]]] += w;
    K.valuePtr()[p.diagonal[edges[e][1]]] += w;
  }
  for (int i = 0; i < s.node_count(); ++i) K.valuePtr()[p.diagonal[i]] += 0.01 * (i % 7);
  K.valuePtr()[p.diagonal[0]] += 1.0;  // SPD
  SparseLdlt ldlt;
  ldlt.analyze(K);
  ASSERT_TRUE(ldlt.factorize(K));
  const Vec b = Vec::Random(s.node_count());
  Vec x(s.node_count());
  ldlt.solve(b.data(), x.data());
  const Eigen::MatrixXd dense = Eigen::MatrixXd(K);
  const Vec expected = dense.ldlt().solve(b);
  EXPECT_LT((x - expected).norm(), 1e-10 * expected.norm());
  // Refactorising new values on the same pattern.
  for (int i = 0; i < s.node_count(); ++i) K.valuePtr()[p.diagonal[i]] *= 2.0;
  ASSERT_TRUE(ldlt.factorize(K));
  ldlt.solve(b.data(), x.data());
  EXPECT_LT((Eigen::MatrixXd(K) * x - b).norm(), 1e-10 * b.norm());
}

}  // namespace
}  // namespace vdm
