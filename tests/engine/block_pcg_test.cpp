// Block PCG: every column is the PCG of krylov.hpp on its own system (same iterations, same
// solution to round-off), with its own stop; zero and already-solved columns stay put.
#include <gtest/gtest.h>

#include "engine/axis_incomplete_cholesky.hpp"
#include "engine/block_pcg.hpp"
#include "engine/incomplete_cholesky.hpp"
#include "engine/stiffness.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

struct Fixture {
  axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  AxisIncompleteCholesky ic;
  Fixture() {
    axis_test::gather(s, K);
    ic.analyze(K);
    ic.factorize(K);
  }
};

template <int W>
void solve_block(const Fixture& f, const std::vector<double>& b, std::vector<double>& x, const double* thr,
                 std::array<KrylovResult, W>& res, int max_iter = 500) {
  BlockPcgWorkspace w;
  auto op = [&f](const double* in, double* out, double* dot) { multiply_block<W>(f.K, in, out, dot); };
  auto pre = [&f](const double* in, double* out, double* dot) { f.ic.apply<W>(in, out, dot); };
  block_pcg<W>(op, pre, f.s.model.n, b.data(), x.data(), thr, max_iter, w, res);
}

TEST(BlockPcg, EveryColumnIsItsOwnPcg) {
  const Fixture f;
  const int n = f.s.model.n, W = 6;
  std::vector<double> b(size_t(n) * W), x(size_t(n) * W, 0.0);
  double thr[W];
  for (int c = 0; c < W; ++c) {
    double bn = 0;
    for (int i = 0; i < n; ++i) {
      b[size_t(i) * W + c] = std::sin(0.05 * i * (c + 1)) + (c == 2 ? 3.0 : 0.0);
      bn += b[size_t(i) * W + c] * b[size_t(i) * W + c];
    }
    thr[c] = (c < 3 ? 1e-8 : 1e-4) * std::sqrt(bn);  // different stops per column
    if (c == 4)  // a warm start near the answer for one column
      for (int i = 0; i < n; ++i) x[size_t(i) * W + c] = 0.01 * b[size_t(i) * W + c];
  }
  const std::vector<double> x0 = x;
  std::array<KrylovResult, W> res;
  solve_block<W>(f, b, x, thr, res);
  std::vector<int> iterations;
  for (int c = 0; c < W; ++c) {
    const SpMat P = axis_test::permuted(f.s.K[size_t(axis_of<W>(c))], f.s.perm);
    IncompleteCholesky ic;
    ic.analyze(P);
    ic.factorize(P);
    Vec bc(n), xc(n);
    for (int i = 0; i < n; ++i) {
      bc[i] = b[size_t(i) * W + c];
      xc[i] = x0[size_t(i) * W + c];
    }
    PcgWorkspace w;
    auto op = [&P](const double* in, double* out) { symmetric_multiply(P, in, out); };
    auto pre = [&ic](const double* in, double* out) { ic.apply(in, out); };
    const KrylovResult one = pcg(op, pre, bc, xc, thr[c] / bc.norm(), 500, w);
    EXPECT_TRUE(res[size_t(c)].converged);
    EXPECT_EQ(res[size_t(c)].iterations, one.iterations) << "column " << c;
    double err = 0;
    for (int i = 0; i < n; ++i) err = std::max(err, std::abs(x[size_t(i) * W + c] - xc[i]));
    EXPECT_LE(err, 1e-9 * xc.cwiseAbs().maxCoeff()) << "column " << c;
    // The residual meets the column's own threshold.
    const Vec r = bc - P * Eigen::Map<const Vec, 0, Eigen::InnerStride<>>(x.data() + c, n, Eigen::InnerStride<>(W));
    EXPECT_LE(r.norm(), thr[c] * (1 + 1e-9)) << "column " << c;
    iterations.push_back(res[size_t(c)].iterations);
  }
  // The loose columns stopped earlier than the tight ones.
  EXPECT_LT(iterations[3], iterations[0]);
}

TEST(BlockPcg, ZeroAndSolvedColumnsAreLeftAlone) {
  const Fixture f;
  const int n = f.s.model.n, W = 3;
  std::vector<double> b(size_t(n) * W, 0.0), x(size_t(n) * W, 0.0);
  for (int i = 0; i < n; ++i) {
    b[size_t(i) * W + 0] = 1.0;   // to solve
    x[size_t(i) * W + 1] = 5.0;   // b = 0: x must become 0
  }
  // Column 2: x already the solution of K^z x = K^z * ones.
  std::vector<double> ones(size_t(n) * W, 1.0), kx(size_t(n) * W);
  double dot[W];
  multiply_block<W>(f.K, ones.data(), kx.data(), dot);
  for (int i = 0; i < n; ++i) {
    b[size_t(i) * W + 2] = kx[size_t(i) * W + 2];
    x[size_t(i) * W + 2] = 1.0;
  }
  const double thr[W] = {1e-8 * std::sqrt(double(n)), 1.0, 1e-8};
  std::array<KrylovResult, W> res;
  solve_block<W>(f, b, x, thr, res);
  EXPECT_GT(res[0].iterations, 3);
  EXPECT_EQ(res[1].iterations, 0);
  EXPECT_EQ(res[2].iterations, 0);
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(x[size_t(i) * W + 1], 0.0);
    EXPECT_EQ(x[size_t(i) * W + 2], 1.0);  // untouched while column 0 iterated
  }
}

TEST(BlockPcg, AnIndefiniteColumnBreaksDownAloneAndTheOthersConverge) {
  Fixture f;
  const int n = f.s.model.n, W = 3;
  // K^y's diagonal made negative (its off-diagonal values, shared with the other axes, are
  // negative too): K^y is negative definite along the preconditioned residual of b = 1 (a
  // positive vector, the factors being of an M-matrix), and PCG breaks down on it at once.
  for (int i = 0; i < n; ++i) f.K.diag[3 * size_t(i) + 1] = -f.K.diag[3 * size_t(i) + 1];
  std::vector<double> b(size_t(n) * W, 1.0), x(size_t(n) * W, 0.0);
  const double t = 1e-8 * std::sqrt(double(n));
  const double thr[W] = {t, t, t};
  std::array<KrylovResult, W> res;
  solve_block<W>(f, b, x, thr, res);
  EXPECT_TRUE(res[0].converged);
  EXPECT_FALSE(res[1].converged);
  EXPECT_TRUE(res[2].converged);
  for (int i = 0; i < n; ++i) EXPECT_TRUE(std::isfinite(x[size_t(i) * W + 1]));
}

}  // namespace
}  // namespace vdm
