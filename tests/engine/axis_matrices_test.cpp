// The three axes' matrices stored together multiply a block of vectors exactly as each
// axis's matrix multiplies its own vector.
#include <gtest/gtest.h>

#include <cstring>

#include "engine/axis_matrices.hpp"
#include "engine/geometry.hpp"
#include "engine/stiffness.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

// K's block product against each axis's matrix in `ref` (source numbering), permuted.
template <int W>
void check_block_product(const axis_test::System& s, const std::array<SpMat, 3>& ref, const AxisMatrices& K) {
  const int n = s.model.n;
  std::vector<double> x(size_t(n) * W), y(size_t(n) * W);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c) x[size_t(i) * W + c] = std::sin(0.37 * i + 1.3 * c) + 0.1 * c;
  double dot[W];
  multiply_block<W>(K, x.data(), y.data(), dot);
  for (int c = 0; c < W; ++c) {
    const SpMat P = axis_test::permuted(ref[size_t(axis_of<W>(c))], s.perm);
    Vec xc(n);
    for (int i = 0; i < n; ++i) xc[i] = x[size_t(i) * W + c];
    const Vec yc = P * xc;
    double err = 0;
    for (int i = 0; i < n; ++i) err = std::max(err, std::abs(y[size_t(i) * W + c] - yc[i]));
    EXPECT_LE(err, 1e-12 * yc.cwiseAbs().maxCoeff()) << "column " << c;
    EXPECT_NEAR(dot[c], xc.dot(yc), 1e-12 * std::abs(xc.dot(yc))) << "column " << c;
  }
}

TEST(AxisMatrices, BlockProductMatchesEachAxisInThePermutedOrder) {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  axis_test::gather(s, K);
  check_block_product<3>(s, s.K, K);
  check_block_product<6>(s, s.K, K);
}

// The solver's gather: from the edge weights and diagonals of the unmasked K, with the
// constrained entries eliminated and springs on the free diagonal, equals mask_constrained()
// on the assembled matrices plus the springs. Gathered twice with different masks: nothing of
// the first mask stays.
TEST(AxisMatrices, GatherFromEdgeWeightsEliminatesTheConstrainedEntries) {
  const axis_test::System s = axis_test::make_system();
  const TissueModel& m = s.model;
  const AxisStiffness k = axis_test::edge_stiffness(m);
  std::array<SpMat, 3> full = {m.pattern.matrix, m.pattern.matrix, m.pattern.matrix};
  to_sparse(m.pattern, k, full);
  // The system's masks (bottom cap on every axis, a band on y), and another one to gather first.
  FlagMat mask(m.n, 3), other(m.n, 3);
  NodeMat springs(m.n, 3);
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      mask(i, d) = m.rest.positions(i, 2) < -0.025 || (d == 1 && std::abs(m.rest.positions(i, 0)) < 0.005);
      other(i, d) = m.rest.positions(i, 2) > 0.01 || (d == 0 && i % 5 == 0);
      springs(i, d) = 1e3 * (1.0 + std::sin(0.3 * i + d));
    }
  std::array<SpMat, 3> ref;
  for (int d = 0; d < 3; ++d) {
    ref[size_t(d)] = m.pattern.matrix;
    mask_constrained(full[size_t(d)], mask.col(d).data(), ref[size_t(d)]);
  }
  for (int d = 0; d < 3; ++d) EXPECT_EQ(SpMat(ref[size_t(d)] - s.K[size_t(d)]).norm(), 0.0) << "axis " << d;
  AxisMatrices K;
  K.analyze(m.pattern, s.perm);
  K.gather(k, other, &springs);
  K.gather(k, mask, nullptr);
  check_block_product<3>(s, ref, K);
  check_block_product<6>(s, ref, K);
  // With springs: on the free diagonal only.
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i)
      if (!mask(i, d)) ref[size_t(d)].coeffRef(i, i) += springs(i, d);
  K.gather(k, mask, &springs);
  check_block_product<3>(s, ref, K);
  check_block_product<6>(s, ref, K);
}

// The gathered values bit for bit: each entry -w_e of its edge, +0 in the rows and columns of
// the nodes constrained on every axis; the diagonal K's (plus the spring) on a free entry, 1
// on a constrained one; the rows constrained on some axes only listed first. With a mask
// whose held region touches itself (rows and columns of neighbouring held nodes) and
// springs, then without springs, then (the same mask: only the values copied) with new
// values.
TEST(AxisMatrices, GatheredValuesAreExactlyTheEliminatedOnes) {
  const axis_test::System s = axis_test::make_system();
  const TissueModel& m = s.model;
  AxisStiffness k = axis_test::edge_stiffness(m);
  FlagMat mask(m.n, 3);
  NodeMat springs(m.n, 3);
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) {
      mask(i, d) = m.rest.positions(i, 2) < -0.02 || (d == 2 && m.rest.positions(i, 0) > 0.03);
      springs(i, d) = 10.0 * (1.0 + std::cos(0.7 * i + d));
    }
  AxisMatrices K;
  K.analyze(m.pattern, s.perm);
  for (int round = 0; round < 3; ++round) {
    const NodeMat* sp = round == 0 ? &springs : nullptr;
    if (round == 2) {  // new values, the same mask
      k.weight *= 1.7;
      k.diagonal *= 1.3;
    }
    K.gather(k, mask, sp);
    auto full = [&](int row) { return mask.row(s.perm[size_t(row)]).minCoeff() != 0; };
    int partial = 0;
    for (int i = 0; i < K.n; ++i) {
      const int node = s.perm[size_t(i)];
      const int count = mask(node, 0) + mask(node, 1) + mask(node, 2);
      partial += count > 0 && count < 3;
      for (int d = 0; d < 3; ++d) {
        const double want = mask(node, d) ? 1.0 : k.diagonal(node, d) + (sp ? springs(node, d) : 0.0);
        EXPECT_EQ(std::memcmp(&K.diag[3 * size_t(i) + size_t(d)], &want, sizeof want), 0) << i << " " << d;
        EXPECT_EQ(K.constrained(i, d), mask(node, d) != 0);
      }
      for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p) {
        const double want = full(i) || full(K.column(size_t(p))) ? 0.0 : -k.weight[K.off_edge[size_t(p)]];
        EXPECT_EQ(std::memcmp(&K.off[size_t(p)], &want, sizeof want), 0) << "entry " << p;
      }
    }
    ASSERT_GT(partial, 0);
    EXPECT_EQ(K.partial_count, partial);
    for (int t = 0; t < K.partial_count; ++t) {
      const int node = s.perm[size_t(K.held_rows[size_t(t)])];
      const int count = mask(node, 0) + mask(node, 1) + mask(node, 2);
      EXPECT_TRUE(count > 0 && count < 3);
    }
  }
}

TEST(AxisMatrices, RowsHoldTheOffDiagonalEntriesInAscendingColumns) {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  K.analyze(s.model.pattern, s.perm);
  EXPECT_EQ(long(K.col6.size()) + K.n, long(s.model.pattern.matrix.nonZeros()));
  for (int i = 0; i < K.n; ++i)
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p) {
      EXPECT_NE(K.column(size_t(p)), i);
      if (p > K.start[size_t(i)]) {
        EXPECT_LT(K.column(size_t(p) - 1), K.column(size_t(p)));
      }
    }
}

}  // namespace
}  // namespace vdm
