// Block PCG: every column is the PCG of krylov.hpp on its own system (same iterations, same
// solution to round-off), with its own stop; zero and already-solved columns stay put.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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
  auto pre = [&f](const double* in, double* out, double* dot, const double* live) {
    f.ic.apply<W>(in, out, dot, live);
  };
  block_pcg<W>(op, pre, f.s.model.n, b.data(), x.data(), thr, max_iter, w, res);
}

// The column kernels (multiply_axis, apply_axis on a column taken out of the block),
// counting their calls.
template <int W>
struct CountedColumns {
  const Fixture& f;
  int* calls;
  double multiply(int c, const double* in, double* out) const {
    ++*calls;
    return multiply_axis(f.K, axis_of<W>(c), in, out);
  }
  double apply(int c, const double* in, double* out) const { return f.ic.apply_axis(axis_of<W>(c), in, out); }
};

template <int W>
void solve_with_columns(const Fixture& f, const std::vector<double>& b, std::vector<double>& x, const double* thr,
                        std::array<KrylovResult, W>& res, int* calls) {
  BlockPcgWorkspace w;
  auto op = [&f](const double* in, double* out, double* dot) { multiply_block<W>(f.K, in, out, dot); };
  auto pre = [&f](const double* in, double* out, double* dot, const double* live) {
    f.ic.apply<W>(in, out, dot, live);
  };
  block_pcg<W>(op, pre, f.s.model.n, b.data(), x.data(), thr, 500, w, res, CountedColumns<W>{f, calls});
}

// Column c of the block kernels' results from the one-vector kernels on column c taken out of
// the block: the same bits, and n entries written, no more (the fixture has entries
// constrained on one axis only: the partial rows' fix-up too).
template <int W>
void expect_column_kernels_match(const Fixture& f) {
  const int n = f.s.model.n;
  std::vector<double> in(size_t(n) * W), wide(size_t(n) * W), in_c(static_cast<size_t>(n)), narrow(size_t(n) + 1);
  for (size_t k = 0; k < in.size(); ++k) in[k] = std::sin(0.37 * double(k)) + 0.2;
  auto take = [&](int c) {
    for (int i = 0; i < n; ++i) in_c[size_t(i)] = in[size_t(i) * W + size_t(c)];
    std::fill(narrow.begin(), narrow.end(), -7.0);
  };
  double dot[W];
  multiply_block<W>(f.K, in.data(), wide.data(), dot);
  for (int c = 0; c < W; ++c) {
    take(c);
    const double d = multiply_axis(f.K, axis_of<W>(c), in_c.data(), narrow.data());
    EXPECT_EQ(d, dot[c]) << "W " << W << " column " << c;
    for (int i = 0; i < n; ++i)
      ASSERT_EQ(narrow[size_t(i)], wide[size_t(i) * W + size_t(c)])
          << "product, W " << W << " column " << c << " row " << i;
    EXPECT_EQ(narrow[size_t(n)], -7.0);
  }
  f.ic.apply<W>(in.data(), wide.data(), dot);
  for (int c = 0; c < W; ++c) {
    take(c);
    const double d = f.ic.apply_axis(axis_of<W>(c), in_c.data(), narrow.data());
    EXPECT_EQ(d, dot[c]) << "W " << W << " column " << c;
    for (int i = 0; i < n; ++i)
      ASSERT_EQ(narrow[size_t(i)], wide[size_t(i) * W + size_t(c)])
          << "MIC(0), W " << W << " column " << c << " row " << i;
    EXPECT_EQ(narrow[size_t(n)], -7.0);
  }
}

TEST(BlockPcg, ColumnKernelsAreTheBlockKernelsColumnByColumn) {
  Fixture f;
  f.ic.factorize(f.K, 0.9);  // the solver's modified factors
  expect_column_kernels_match<3>(f);
  expect_column_kernels_match<6>(f);
}

// Once one column is left iterating it is taken out of the block and runs on the column
// kernels: the same iterates bit for bit, whether it is alone from the start or the last of
// several to stop, and the block's other columns of x as the block path leaves them (the
// start is not zero: the column goes back among them).
template <int W>
void expect_column_left_alone_matches(const Fixture& f, int last) {
  const int n = f.s.model.n;
  for (bool alone_from_start : {false, true}) {
    std::vector<double> b(size_t(n) * W, 0.0), x(size_t(n) * W, 0.0);
    for (size_t k = 0; k < x.size(); ++k) x[k] = 0.01 * std::sin(0.3 * double(k));
    double thr[W];
    for (int c = 0; c < W; ++c) {
      double bn = 0;
      for (int i = 0; i < n; ++i) {
        const double v = alone_from_start && c != last ? 0.0 : std::cos(0.07 * i * (c + 2)) + 0.5;
        b[size_t(i) * W + c] = v;
        bn += v * v;
      }
      thr[c] = (c == last ? 1e-10 : 1e-3) * std::sqrt(bn);  // column `last` the last to stop
    }
    std::vector<double> x_wide = x, x_narrow = x;
    std::array<KrylovResult, W> wide, narrow;
    int calls = 0;
    solve_block<W>(f, b, x_wide, thr, wide);
    solve_with_columns<W>(f, b, x_narrow, thr, narrow, &calls);
    EXPECT_GT(calls, 3) << "W " << W << ": the column kernels took over (alone from the start: " << alone_from_start
                        << ")";
    EXPECT_EQ(x_narrow, x_wide) << "W " << W << ", alone from the start: " << alone_from_start;
    for (int c = 0; c < W; ++c) {
      EXPECT_EQ(narrow[size_t(c)].iterations, wide[size_t(c)].iterations) << c;
      EXPECT_EQ(narrow[size_t(c)].converged, wide[size_t(c)].converged) << c;
      EXPECT_EQ(narrow[size_t(c)].relative_residual, wide[size_t(c)].relative_residual) << c;
    }
    EXPECT_TRUE(wide[size_t(last)].converged);
    EXPECT_GT(wide[size_t(last)].iterations, wide[0].iterations);
  }
}

TEST(BlockPcg, AColumnLeftAloneRunsTheSameIteratesOnTheColumnKernels) {
  const Fixture f;
  expect_column_left_alone_matches<6>(f, 3);
  expect_column_left_alone_matches<3>(f, 2);
}

// The start's residual in one pass (residual_block) against the product and block_pcg's own
// passes: the same bits, in place (r = b) or not; and nothing written when some row is
// constrained on some axes only (the fixture's y band).
template <int W>
void expect_residual_matches(const AxisMatrices& K, int n) {
  std::vector<double> b(size_t(n) * W), x(size_t(n) * W), q(size_t(n) * W), r(size_t(n) * W);
  for (size_t k = 0; k < b.size(); ++k) {
    b[k] = std::cos(0.11 * double(k)) - 0.3;
    x[k] = std::sin(0.37 * double(k)) + 0.2;
  }
  double dot[W], bn[W] = {}, rn[W] = {};
  multiply_block<W>(K, x.data(), q.data(), dot);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c) {
      const size_t k = size_t(i) * W + size_t(c);
      bn[c] += b[k] * b[k];
      r[k] = b[k] - q[k];
      rn[c] += r[k] * r[k];
    }
  std::vector<double> out(b.size(), -7.0), inplace = b;
  double bn2[W], rn2[W], bn3[W], rn3[W];
  ASSERT_TRUE(residual_block<W>(K, b.data(), x.data(), out.data(), bn2, rn2));
  ASSERT_TRUE(residual_block<W>(K, inplace.data(), x.data(), inplace.data(), bn3, rn3));
  EXPECT_EQ(out, r) << "W " << W;
  EXPECT_EQ(inplace, r) << "W " << W << ", in place";
  // b in the source's numbering (n x 3 column-major per system, vector d G + g of the block
  // column d of system g, row i at node_of[i]), as the solver hands its right-hand sides.
  constexpr int G = W / 3;
  std::vector<double> src(size_t(n) * W);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c)
      src[size_t(c % G) * 3 * size_t(n) + size_t(c / G) * size_t(n) + size_t(K.node_of[size_t(i)])] =
          b[size_t(i) * W + size_t(c)];
  std::array<const double*, G> b_src;
  for (int g = 0; g < G; ++g) b_src[size_t(g)] = src.data() + size_t(g) * 3 * size_t(n);
  std::vector<double> gathered(b.size(), -7.0);
  double bn4[W], rn4[W];
  ASSERT_TRUE(residual_block<W>(K, b_src, x.data(), gathered.data(), bn4, rn4));
  EXPECT_EQ(gathered, r) << "W " << W << ", b in the source's numbering";
  for (int c = 0; c < W; ++c) {
    EXPECT_EQ(bn2[c], bn[c]) << "W " << W << " column " << c;
    EXPECT_EQ(rn2[c], rn[c]) << "W " << W << " column " << c;
    EXPECT_EQ(bn3[c], bn[c]) << "W " << W << " column " << c;
    EXPECT_EQ(rn3[c], rn[c]) << "W " << W << " column " << c;
    EXPECT_EQ(bn4[c], bn[c]) << "W " << W << " column " << c;
    EXPECT_EQ(rn4[c], rn[c]) << "W " << W << " column " << c;
  }
}

// A fixture whose constrained rows are all constrained on every axis (the bottom cap).
struct FullRowsFixture : Fixture {
  FullRowsFixture() {
    for (int i = 0; i < s.model.n; ++i) {
      const bool cap = s.mask.row(i).minCoeff() != 0;
      for (int d = 0; d < 3; ++d) s.mask(i, d) = cap;
    }
    K.gather(s.k, s.mask, nullptr);
    ic.factorize(K, 0.9);
  }
};

TEST(BlockPcg, TheStartsResidualInOnePassIsTheProductAndTheNormsPasses) {
  const FullRowsFixture f;
  ASSERT_EQ(f.K.partial_count, 0);
  expect_residual_matches<3>(f.K, f.s.model.n);
  expect_residual_matches<6>(f.K, f.s.model.n);
  const Fixture g;  // rows constrained on y only: not in one pass
  ASSERT_GT(g.K.partial_count, 0);
  const int n = g.s.model.n;
  std::vector<double> b(size_t(n) * 6, 1.0), x(size_t(n) * 6, 2.0), r(size_t(n) * 6, -7.0);
  double bn[6] = {-1, -1, -1, -1, -1, -1}, rn[6] = {-1, -1, -1, -1, -1, -1};
  EXPECT_FALSE(residual_block<6>(g.K, b.data(), x.data(), r.data(), bn, rn));
  EXPECT_FALSE(residual_block<6>(g.K, std::array<const double*, 2>{b.data(), b.data() + 3 * n}, x.data(), r.data(), bn, rn));
  EXPECT_EQ(r, std::vector<double>(size_t(n) * 6, -7.0));
  EXPECT_EQ(bn[0], -1.0);
  EXPECT_EQ(rn[5], -1.0);
}

// The column kernels with the one-pass residual: block_pcg's iterates are those it makes
// without them, bit for bit (b given in the residual array itself, as the solver does).
template <int W>
struct ResidualColumns : CountedColumns<W> {
  int* residuals;
  bool residual(const double* b, const double* x, double* r, double* bn, double* rn) const {
    const bool done = residual_block<W>(this->f.K, b, x, r, bn, rn);
    *residuals += done;
    return done;
  }
};

TEST(BlockPcg, TheOnePassResidualGivesTheSameIterates) {
  const FullRowsFixture f;
  const int n = f.s.model.n, W = 6;
  std::vector<double> b(size_t(n) * W), x(size_t(n) * W);
  double thr[W];
  for (int c = 0; c < W; ++c) {
    double bn = 0;
    for (int i = 0; i < n; ++i) {
      const double v = std::cos(0.07 * i * (c + 2)) + 0.5;
      b[size_t(i) * W + c] = v;
      x[size_t(i) * W + c] = 0.1 * std::sin(0.3 * i + c);
      bn += v * v;
    }
    thr[c] = (c == 3 ? 1e-10 : 1e-4) * std::sqrt(bn);
  }
  std::vector<double> x_plain = x, x_fused = x;
  std::array<KrylovResult, W> plain, fused;
  solve_block<W>(f, b, x_plain, thr, plain);
  BlockPcgWorkspace w;
  w.resize(size_t(n) * W);
  std::copy(b.begin(), b.end(), w.r.begin());
  auto op = [&f](const double* in, double* out, double* dot) { multiply_block<W>(f.K, in, out, dot); };
  auto pre = [&f](const double* in, double* out, double* dot, const double* live) {
    f.ic.apply<W>(in, out, dot, live);
  };
  int calls = 0, residuals = 0;
  block_pcg<W>(op, pre, n, w.r.data(), x_fused.data(), thr, 500, w, fused,
               ResidualColumns<W>{{f, &calls}, &residuals});
  EXPECT_EQ(residuals, 1);
  EXPECT_EQ(x_fused, x_plain);
  for (int c = 0; c < W; ++c) {
    EXPECT_EQ(fused[size_t(c)].iterations, plain[size_t(c)].iterations) << c;
    EXPECT_EQ(fused[size_t(c)].converged, plain[size_t(c)].converged) << c;
    EXPECT_EQ(fused[size_t(c)].relative_residual, plain[size_t(c)].relative_residual) << c;
  }
}

// A Galerkin step along a given direction (block_pcg's project hook): here the true error of
// column 0, so that column starts at its solution; column 1 declines; column 2 is solved
// already and is not asked.
struct ProjectingColumns : CountedColumns<3> {
  const std::vector<double>* solution;
  int* asked;
  bool project(int c, double* x, double* r, double& rn, double bn, double threshold, double*) const {
    const int W = 3, n = f.s.model.n;
    ++asked[c];
    EXPECT_GT(std::sqrt(rn), threshold);
    EXPECT_GT(bn, 0.0);
    if (c != 0) return false;
    std::vector<double> v(static_cast<size_t>(n)), kv(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) v[size_t(i)] = (*solution)[size_t(i) * W] - x[size_t(i) * W];
    const double vkv = multiply_axis(f.K, 0, v.data(), kv.data());
    double vr = 0;
    for (int i = 0; i < n; ++i) vr += v[size_t(i)] * r[size_t(i) * W];
    const double t = vr / vkv;
    rn = 0;
    for (int i = 0; i < n; ++i) {
      x[size_t(i) * W] += t * v[size_t(i)];
      r[size_t(i) * W] -= t * kv[size_t(i)];
      rn += r[size_t(i) * W] * r[size_t(i) * W];
    }
    return true;
  }
};

TEST(BlockPcg, AProjectedColumnStartsFromItsGalerkinStep) {
  const Fixture f;
  const int n = f.s.model.n, W = 3;
  std::vector<double> solution(size_t(n) * W), b(size_t(n) * W), x(size_t(n) * W, 0.0);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < W; ++c) solution[size_t(i) * W + c] = std::cos(0.11 * i + c) + 0.2;
  double dot[W];
  multiply_block<W>(f.K, solution.data(), b.data(), dot);
  for (int i = 0; i < n; ++i) x[size_t(i) * W + 2] = solution[size_t(i) * W + 2];
  double thr[W];
  for (int c = 0; c < W; ++c) {
    double bn = 0;
    for (int i = 0; i < n; ++i) bn += b[size_t(i) * W + c] * b[size_t(i) * W + c];
    thr[c] = 1e-8 * std::sqrt(bn);
  }
  std::vector<double> x_plain = x;
  std::array<KrylovResult, W> plain, projected;
  solve_block<W>(f, b, x_plain, thr, plain);
  BlockPcgWorkspace w;
  auto op = [&f](const double* in, double* out, double* d) { multiply_block<W>(f.K, in, out, d); };
  auto pre = [&f](const double* in, double* out, double* d, const double* live) { f.ic.apply<W>(in, out, d, live); };
  int calls = 0, asked[W] = {0, 0, 0};
  block_pcg<W>(op, pre, n, b.data(), x.data(), thr, 500, w, projected,
               ProjectingColumns{{f, &calls}, &solution, asked});
  EXPECT_EQ(asked[0], 1);
  EXPECT_EQ(asked[1], 1);
  EXPECT_EQ(asked[2], 0);
  EXPECT_GT(plain[0].iterations, 3);
  EXPECT_EQ(projected[0].iterations, 0);
  EXPECT_EQ(projected[1].iterations, plain[1].iterations);  // declined: its own PCG
  EXPECT_EQ(projected[2].iterations, 0);
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR(x[size_t(i) * W], solution[size_t(i) * W], 1e-9);
    EXPECT_EQ(x[size_t(i) * W + 1], x_plain[size_t(i) * W + 1]);
  }
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
