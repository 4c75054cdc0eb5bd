// The three axes' matrices stored together multiply a block of vectors exactly as each
// axis's matrix multiplies its own vector.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "engine/axis_matrices.hpp"
#include "engine/geometry.hpp"
#include "engine/stiffness.hpp"
#include "support/axis_systems.hpp"
#include "support/simd_paths.hpp"

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

// The AVX2 kernels on blocks of 6 (engine/simd4.hpp) give the SSE2 ones' bits: the product
// (with rows constrained on some axes only, fixed after the pass, and without), the start's
// residual from a block (apart and in place) and from the source's columns.
TEST(AxisMatrices, Avx2KernelsGiveTheSse2Bits) {
  if (!simd::avx2_supported()) GTEST_SKIP() << "this CPU lacks AVX2: only the SSE2 kernels run here";
  const axis_test::System s = axis_test::make_system();
  const int n = s.model.n;
  AxisMatrices partial, full;
  axis_test::gather(s, partial);
  FlagMat cap = s.mask;  // the bottom cap alone: rows constrained on every axis only
  for (int i = 0; i < n; ++i) cap.row(i).setConstant(cap.row(i).minCoeff());
  full.analyze(s.model.pattern, s.perm);
  full.gather(s.k, cap, nullptr);
  ASSERT_GT(partial.partial_count, 0);
  ASSERT_EQ(full.partial_count, 0);
  const size_t size = size_t(n) * 6;
  std::vector<double> x(size), b(size), src(size);
  for (size_t k = 0; k < size; ++k) {
    x[k] = std::sin(0.37 * double(k)) + 0.2;
    b[k] = std::cos(0.11 * double(k)) - 0.3;
  }
  std::copy(b.begin(), b.end(), src.begin());  // other values read as two n x 3 column-major systems
  const std::array<const double*, 2> b_src = {src.data(), src.data() + 3 * size_t(n)};
  struct Out {
    std::vector<double> y_partial, y_full, r, r_inplace, r_src;
    double dot_partial[6], dot_full[6], bn[6], rn[6], bn_inplace[6], rn_inplace[6], bn_src[6], rn_src[6];
  } out[2];
  simd_test::sse2_then_avx2([&](bool avx2) {
    ASSERT_EQ(simd::avx2_enabled(), avx2);
    Out& o = out[avx2];
    o.y_partial.assign(size, -7.0);
    o.y_full.assign(size, -7.0);
    o.r.assign(size, -7.0);
    o.r_src.assign(size, -7.0);
    o.r_inplace = b;
    multiply_block<6>(partial, x.data(), o.y_partial.data(), o.dot_partial);
    multiply_block<6>(full, x.data(), o.y_full.data(), o.dot_full);
    ASSERT_TRUE(residual_block<6>(full, b.data(), x.data(), o.r.data(), o.bn, o.rn));
    ASSERT_TRUE(residual_block<6>(full, o.r_inplace.data(), x.data(), o.r_inplace.data(), o.bn_inplace, o.rn_inplace));
    ASSERT_TRUE(residual_block<6>(full, b_src, x.data(), o.r_src.data(), o.bn_src, o.rn_src));
  });
  auto same = [](const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
  };
  EXPECT_TRUE(same(out[0].y_partial, out[1].y_partial));
  EXPECT_TRUE(same(out[0].y_full, out[1].y_full));
  EXPECT_TRUE(same(out[0].r, out[1].r));
  EXPECT_TRUE(same(out[0].r_inplace, out[1].r_inplace));
  EXPECT_TRUE(same(out[0].r_src, out[1].r_src));
  EXPECT_TRUE(same(out[0].r, out[0].r_inplace));
  for (int c = 0; c < 6; ++c) {
    EXPECT_EQ(std::memcmp(&out[0].dot_partial[c], &out[1].dot_partial[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].dot_full[c], &out[1].dot_full[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].bn[c], &out[1].bn[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].rn[c], &out[1].rn[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].bn_inplace[c], &out[1].bn_inplace[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].rn_inplace[c], &out[1].rn_inplace[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].bn_src[c], &out[1].bn_src[c], sizeof(double)), 0) << c;
    EXPECT_EQ(std::memcmp(&out[0].rn_src[c], &out[1].rn_src[c], sizeof(double)), 0) << c;
  }
}

// The choice of variant: set_avx2(false) forces SSE2 everywhere; AVX2 only where supported.
TEST(AxisMatrices, TheSse2KernelsCanBeForced) {
  const bool saved = simd::avx2_enabled();
  EXPECT_FALSE(simd::set_avx2(false));
  EXPECT_FALSE(simd::avx2_enabled());
  EXPECT_EQ(simd::set_avx2(true), simd::avx2_supported());
  simd::set_avx2(saved);
}

}  // namespace
}  // namespace vdm
