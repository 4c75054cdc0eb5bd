// IC(0) of the three axes at once is, axis by axis, the single-axis IC(0) of the same
// (permuted) matrix; on a block of vectors it preconditions each with its own axis.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "engine/axis_incomplete_cholesky.hpp"
#include "engine/block_pcg.hpp"
#include "engine/incomplete_cholesky.hpp"
#include "support/axis_systems.hpp"
#include "support/simd_paths.hpp"

namespace vdm {
namespace {

// The factors are stored in float (axis_incomplete_cholesky.hpp): the same factorisation as
// the single-axis one in double to float round-off, 1e-11 when they were doubles.
constexpr double kFloatFactors = 1e-5;

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
    EXPECT_LE(err, kFloatFactors * zc.cwiseAbs().maxCoeff()) << "column " << c;
    EXPECT_NEAR(rz[c], rc.dot(zc), kFloatFactors * std::abs(rc.dot(zc))) << "column " << c;
  }
}

// The test system gathered, its factors analysed (not yet factorised).
struct Analysed {
  const axis_test::System s = axis_test::make_system();
  AxisMatrices K;
  AxisIncompleteCholesky ic;
  Analysed() {
    axis_test::gather(s, K);
    ic.analyze(K);
  }
};

TEST(AxisIncompleteCholesky, EachAxisIsTheSingleAxisFactorisation) {
  Analysed a;
  EXPECT_EQ(a.ic.factorize(a.K), 0);  // M-matrices: no pivot repaired
  check_apply<3>(a.s, a.ic);
  check_apply<6>(a.s, a.ic);
}

TEST(AxisIncompleteCholesky, NonPositivePivotsAreRepairedAndCountedAsForOneAxis) {
  axis_test::System s = axis_test::make_system();
  // One node's K^z diagonal made negative: that pivot and some after it are repaired.
  const int node = s.perm[5];
  ASSERT_FALSE(s.mask(node, 2));
  s.K[2].coeffRef(node, node) = -1.0;
  AxisMatrices K;
  axis_test::gather(s, K);
  K.diag[3 * 5 + 2] = -1.0;  // row 5 here is that node
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
  axis_test::gather(s, K);
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
    if (omega == 1.0) EXPECT_LT(err, kFloatFactors);
    else EXPECT_GT(err, 1e-3);
  }
}

// Factors made for one constrained set and fitted to another (the structured solver's reuse
// across the contact's changes) are a preconditioner of the new system: identity rows where it
// is constrained, SPD, and PCG with them converges to what fresh factors give.
TEST(AxisIncompleteCholesky, FittedToAnotherConstrainedSetPreconditionsItsSystem) {
  const axis_test::System s = axis_test::make_system();
  const TissueModel& m = s.model;
  const AxisStiffness k = axis_test::edge_stiffness(m);
  // Before: the bottom cap held. After: part of it freed, a patch on top pressed (z only).
  FlagMat before(m.n, 3), after(m.n, 3);
  int differ = 0;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      const Vec3 x = m.rest.positions.row(i);
      before(i, d) = x[2] < -0.025;
      after(i, d) = (x[2] < -0.025 && x[0] < 0.01) || (d == 2 && x[2] > 0.02 && x[0] > 0.0);
      differ += before(i, d) != after(i, d);
    }
  ASSERT_GT(differ, 10);
  AxisMatrices K;
  K.analyze(m.pattern, s.perm);
  K.gather(k, before, nullptr);
  AxisIncompleteCholesky fitted, fresh;
  fitted.analyze(K);
  fitted.factorize(K, 0.9);
  K.gather(k, after, nullptr);
  EXPECT_EQ(fitted.fit_to_mask(K), differ);
  EXPECT_EQ(fitted.fit_to_mask(K), 0);  // already fitted
  {
    // The factors' copy by rows of L^T was refitted with L: the same sweeps, bit for bit, as
    // factors whose copy is made afresh from L (load_values copies it whole).
    std::vector<double> values;
    fitted.save_values(values);
    AxisIncompleteCholesky copy;
    copy.analyze(K);
    size_t pos = 0;
    ASSERT_TRUE(copy.load_values(values, pos));
    std::vector<double> in(6 * size_t(m.n)), z1(in.size()), z2(in.size());
    for (size_t e = 0; e < in.size(); ++e) in[e] = std::sin(0.21 * double(e)) + 0.4;
    double d1[6], d2[6];
    fitted.apply<6>(in.data(), z1.data(), d1);
    copy.apply<6>(in.data(), z2.data(), d2);
    EXPECT_EQ(z1, z2);
    fitted.apply<3>(in.data(), z1.data(), d1);
    copy.apply<3>(in.data(), z2.data(), d2);
    EXPECT_EQ(z1, z2);
  }
  fresh.analyze(K);
  fresh.factorize(K, 0.9);
  const int n = m.n;
  std::vector<double> r(3 * size_t(n)), z(3 * size_t(n));
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) r[3 * size_t(i) + size_t(c)] = std::cos(0.37 * i + 1.3 * c) + 0.2;
  double rz[3];
  fitted.apply<3>(r.data(), z.data(), rz);
  for (int c = 0; c < 3; ++c) EXPECT_GT(rz[c], 0.0) << "axis " << c;
  for (size_t e = 0; e < r.size(); ++e)
    if (K.row_mask[e]) {
      EXPECT_EQ(z[e], r[e]) << "entry " << e;  // the identity's row
    }
  // The same system solved with both: the same solution to the tolerance.
  auto solve = [&](const AxisIncompleteCholesky& ic, std::vector<double>& x) {
    auto op = [&K](const double* in, double* out, double* dot) { multiply_block<3>(K, in, out, dot); };
    auto pre = [&ic](const double* in, double* out, double* dot, const double* live) {
      ic.apply<3>(in, out, dot, live);
    };
    double norm = 0;
    for (double b : r) norm += b * b;
    const double t = 1e-12 * std::sqrt(norm);
    const double threshold[3] = {t, t, t};
    BlockPcgWorkspace work;
    std::array<KrylovResult, 3> res;
    x.assign(r.size(), 0.0);
    block_pcg<3>(op, pre, n, r.data(), x.data(), threshold, 500, work, res);
    int its = 0;
    for (const KrylovResult& k : res) {
      EXPECT_TRUE(k.converged);
      its += k.iterations;
    }
    return its;
  };
  std::vector<double> x_fitted, x_fresh;
  const int its_fitted = solve(fitted, x_fitted), its_fresh = solve(fresh, x_fresh);
  double diff = 0, size = 0;
  for (size_t e = 0; e < r.size(); ++e) {
    diff = std::max(diff, std::abs(x_fitted[e] - x_fresh[e]));
    size = std::max(size, std::abs(x_fresh[e]));
  }
  EXPECT_LT(diff, 1e-9 * size);
  // Older factors precondition less well, but still well (without the refit's identity
  // rows the constrained entries would not even be solved exactly).
  EXPECT_LE(its_fitted, 2 * its_fresh) << its_fitted << " against " << its_fresh;
}

// The AVX2 sweeps on blocks of 6 (engine/simd4.hpp) give the SSE2 ones' bits: with IC(0)
// and relaxed MIC(0) factors, and with factors fitted to another constrained set.
TEST(AxisIncompleteCholesky, Avx2SweepsGiveTheSse2Bits) {
  if (!simd::avx2_supported()) GTEST_SKIP() << "this CPU lacks AVX2: only the SSE2 sweeps run here";
  const axis_test::System s = axis_test::make_system();
  const TissueModel& m = s.model;
  AxisMatrices K;
  axis_test::gather(s, K);
  FlagMat other(m.n, 3);  // the bottom cap held on every axis, a patch on top on z
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      const Vec3 x = m.rest.positions.row(i);
      other(i, d) = x[2] < -0.025 || (d == 2 && x[2] > 0.02 && x[0] > 0.0);
    }
  const size_t size = 6 * size_t(m.n);
  std::vector<double> r(size);
  for (size_t e = 0; e < size; ++e) r[e] = std::cos(0.21 * double(e)) - 0.1;
  AxisIncompleteCholesky ic;
  ic.analyze(K);
  for (int round = 0; round < 3; ++round) {
    if (round < 2) {
      ic.factorize(K, round == 0 ? 0.0 : 0.9);
    } else {
      K.gather(s.k, other, nullptr);
      ASSERT_GT(ic.fit_to_mask(K), 0);
    }
    std::vector<double> z[2];
    double rz[2][6];
    simd_test::sse2_then_avx2([&](bool avx2) {
      z[avx2].assign(size, -7.0);
      ic.apply<6>(r.data(), z[avx2].data(), rz[avx2]);
    });
    EXPECT_EQ(std::memcmp(z[0].data(), z[1].data(), size * sizeof(double)), 0) << "round " << round;
    EXPECT_EQ(std::memcmp(rz[0], rz[1], sizeof rz[0]), 0) << "round " << round;
  }
}

// Stopped vectors (live = 0): their r is taken as zero, the same bits as zeroing those entries
// of r first, in every variant (W = 3; W = 6 with SSE2 and AVX2), r itself untouched; the live
// ones as without the mask; also masks of all live (nothing changes) and of none (z = 0).
template <int W>
void expect_live_lanes_match(const AxisIncompleteCholesky& ic, int n, bool avx2) {
  const size_t size = size_t(n) * W;
  std::vector<double> r(size);
  for (size_t e = 0; e < size; ++e) r[e] = std::cos(0.29 * double(e)) - 0.2;
  const double patterns[3][6] = {{1, 0, 0, 1, 1, 0}, {1, 1, 1, 1, 1, 1}, {0, 0, 0, 0, 0, 0}};
  for (const double* live : patterns) {
    std::vector<double> zeroed = r, z_masked(size, -7.0), z_zeroed(size, -7.0);
    for (size_t e = 0; e < size; ++e)
      if (live[e % W] == 0.0) zeroed[e] = 0.0;
    const std::vector<double> r_before = r;
    double rz_masked[W], rz_zeroed[W];
    ic.apply<W>(r.data(), z_masked.data(), rz_masked, live);
    ic.apply<W>(zeroed.data(), z_zeroed.data(), rz_zeroed);
    EXPECT_EQ(std::memcmp(z_masked.data(), z_zeroed.data(), size * sizeof(double)), 0) << "W " << W << " avx2 " << avx2;
    EXPECT_EQ(std::memcmp(rz_masked, rz_zeroed, sizeof rz_masked), 0) << "W " << W << " avx2 " << avx2;
    EXPECT_EQ(r, r_before);
    for (int c = 0; c < W; ++c) {
      if (live[c] == 0.0) {
        EXPECT_EQ(z_masked[size_t(c)], 0.0) << "W " << W << " column " << c;
      }
    }
  }
}

TEST(AxisIncompleteCholesky, StoppedVectorsAreTakenAsZero) {
  Analysed a;
  a.ic.factorize(a.K, 0.9);
  const int n = a.s.model.n;
  expect_live_lanes_match<3>(a.ic, n, false);
  simd_test::sse2_then_avx2([&](bool avx2) { expect_live_lanes_match<6>(a.ic, n, avx2); });
}

}  // namespace
}  // namespace vdm
