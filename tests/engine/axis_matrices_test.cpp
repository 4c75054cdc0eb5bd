// The three axes' matrices stored together multiply a block of vectors exactly as each
// axis's matrix multiplies its own vector.
#include <gtest/gtest.h>

#include "engine/axis_matrices.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

template <int W>
void check_block_product(const axis_test::System& s, const AxisMatrices& K) {
  const int n = s.model.n;
  std::vector<double> x(size_t(n) * W), y(size_t(n) * W);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c) x[size_t(i) * W + c] = std::sin(0.37 * i + 1.3 * c) + 0.1 * c;
  double dot[W];
  multiply_block<W>(K, x.data(), y.data(), dot);
  for (int c = 0; c < W; ++c) {
    const SpMat P = axis_test::permuted(s.K[size_t(axis_of<W>(c))], s.perm);
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
  K.analyze(s.model.pattern.matrix, s.perm);
  K.gather(s.K);
  check_block_product<3>(s, K);
  check_block_product<6>(s, K);
}

TEST(AxisMatrices, RowsHoldTheOffDiagonalEntriesInAscendingColumns) {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  K.analyze(s.model.pattern.matrix, s.perm);
  EXPECT_EQ(long(K.col.size()) + K.n, long(s.model.pattern.matrix.nonZeros()));
  for (int i = 0; i < K.n; ++i)
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p) {
      EXPECT_NE(K.col[size_t(p)], i);
      if (p > K.start[size_t(i)]) {
        EXPECT_LT(K.col[size_t(p) - 1], K.col[size_t(p)]);
      }
    }
}

}  // namespace
}  // namespace vdm
