// IC(0) of the three axes at once is, axis by axis, the single-axis IC(0) of the same
// (permuted) matrix; on a block of vectors it preconditions each with its own axis.
#include <gtest/gtest.h>

#include "engine/axis_incomplete_cholesky.hpp"
#include "engine/incomplete_cholesky.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

template <int W>
void check_apply(const axis_test::System& s, const AxisIncompleteCholesky& ic) {
  const int n = s.model.n;
  std::vector<double> r(size_t(n) * W), z(size_t(n) * W);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c) r[size_t(i) * W + c] = std::cos(0.21 * i - 0.7 * c) + 0.05 * c;
  double rz[W];
  ic.apply<W>(r.data(), z.data(), rz);
  for (int c = 0; c < W; ++c) {
    const SpMat P = axis_test::permuted(s.K[size_t(axis_of<W>(c))], s.perm);
    IncompleteCholesky one;
    one.analyze(P);
    one.factorize(P);
    Vec rc(n), zc(n);
    for (int i = 0; i < n; ++i) rc[i] = r[size_t(i) * W + c];
    one.apply(rc.data(), zc.data());
    double err = 0;
    for (int i = 0; i < n; ++i) err = std::max(err, std::abs(z[size_t(i) * W + c] - zc[i]));
    EXPECT_LE(err, 1e-11 * zc.cwiseAbs().maxCoeff()) << "column " << c;
    EXPECT_NEAR(rz[c], rc.dot(zc), 1e-11 * std::abs(rc.dot(zc))) << "column " << c;
  }
}

TEST(AxisIncompleteCholesky, EachAxisIsTheSingleAxisFactorisation) {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  K.analyze(s.model.pattern.matrix, s.perm);
  K.gather(s.K);
  AxisIncompleteCholesky ic;
  ic.analyze(K);
  EXPECT_EQ(ic.factorize(K), 0);  // M-matrices: no pivot repaired
  check_apply<3>(s, ic);
  check_apply<6>(s, ic);
}

TEST(AxisIncompleteCholesky, NonPositivePivotsAreRepairedAndCountedAsForOneAxis) {
  axis_test::System s = axis_test::make_system();
  // One node's K^z diagonal made negative: that pivot and some after it are repaired.
  const int node = s.perm[5];
  s.K[2].coeffRef(node, node) = -1.0;
  AxisMatrices K;
  K.analyze(s.model.pattern.matrix, s.perm);
  K.gather(s.K);
  AxisIncompleteCholesky ic;
  ic.analyze(K);
  const SpMat P = axis_test::permuted(s.K[2], s.perm);
  IncompleteCholesky one;
  one.analyze(P);
  const int expected = one.factorize(P);
  EXPECT_GE(expected, 1);
  EXPECT_EQ(ic.factorize(K), expected);
  check_apply<3>(s, ic);
}

// MIC(0) (omega = 1) keeps the row sums: L L^T 1 = K 1, so the preconditioner maps K 1 back
// to 1 exactly (to round-off); plain IC(0) does not.
TEST(AxisIncompleteCholesky, ModifiedFactorisationKeepsTheRowSums) {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  K.analyze(s.model.pattern.matrix, s.perm);
  K.gather(s.K);
  const int n = s.model.n;
  std::vector<double> ones(3 * size_t(n), 1.0), k1(3 * size_t(n)), z(3 * size_t(n));
  double dot[3];
  multiply_block<3>(K, ones.data(), k1.data(), dot);
  AxisIncompleteCholesky ic;
  ic.analyze(K);
  for (double omega : {1.0, 0.0}) {
    EXPECT_EQ(ic.factorize(K, omega), 0);
    ic.apply<3>(k1.data(), z.data(), dot);
    double err = 0;
    for (double v : z) err = std::max(err, std::abs(v - 1.0));
    if (omega == 1.0) EXPECT_LT(err, 1e-10);
    else EXPECT_GT(err, 1e-3);
  }
}

}  // namespace
}  // namespace vdm
