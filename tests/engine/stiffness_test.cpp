// The edge-weight kernels of the stiffness against the assembled sparse matrices: the
// product K X per axis, and the eliminated right-hand side (constrained values moved to the
// right, identity rows) against the same elimination done with the full matrix.
#include <gtest/gtest.h>
#include <cstring>

#include "engine/stiffness.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

struct Kernels {
  axis_test::System s = axis_test::make_system();
  std::array<SpMat, 3> full;  // unmasked, as the step's edge weights and diagonals give it
  NodeMat x, f, u_fixed;
  Kernels() {
    const TissueModel& m = s.model;
    full = {m.pattern.matrix, m.pattern.matrix, m.pattern.matrix};
    to_sparse(m.pattern, s.k, full);
    x.resize(m.n, 3);
    f.resize(m.n, 3);
    u_fixed = NodeMat::Zero(m.n, 3);
    for (int i = 0; i < m.n; ++i)
      for (int d = 0; d < 3; ++d) {
        x(i, d) = std::sin(0.31 * i + 1.7 * d) + 0.2;
        f(i, d) = std::cos(0.13 * i - 0.4 * d);
        if (s.mask(i, d)) u_fixed(i, d) = 1e-3 * (1.0 + std::sin(0.7 * i + d));
      }
  }
};

TEST(Stiffness, ProductFromEdgeWeightsIsTheAssembledMatricesProduct) {
  const Kernels t;
  NodeMat y(t.s.model.n, 3);
  multiply(t.s.model.pattern, t.s.k, t.x, y);
  for (int d = 0; d < 3; ++d) {
    const Vec ref = t.full[size_t(d)] * t.x.col(d);
    EXPECT_LE((y.col(d) - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff()) << "axis " << d;
  }
}

// The system's mask holds a cap on every axis and a band on y only: edges between free and
// constrained entries on one axis but not the others.
TEST(Stiffness, EliminatedRightHandSideMovesTheConstrainedValuesToTheRight) {
  const Kernels t;
  const TissueModel& m = t.s.model;
  NodeMat rhs(m.n, 3);
  std::vector<std::uint8_t> scratch;
  eliminate_rhs(m.pattern, t.s.k, t.s.mask, &t.f, t.u_fixed, rhs, scratch);
  int coupled = 0;
  for (int d = 0; d < 3; ++d) {
    // K_full u = f on the free rows with u = u_fixed on the constrained entries: the free
    // rows' right-hand side is f - K_full u_fixed (u_fixed zero on the free entries).
    const Vec moved = t.full[size_t(d)] * t.u_fixed.col(d);
    for (int i = 0; i < m.n; ++i) {
      if (t.s.mask(i, d)) {
        EXPECT_EQ(rhs(i, d), t.u_fixed(i, d)) << "node " << i << " axis " << d;
        continue;
      }
      EXPECT_NEAR(rhs(i, d), t.f(i, d) - moved[i], 1e-12 * (std::abs(t.f(i, d)) + std::abs(moved[i])))
          << "node " << i << " axis " << d;
      coupled += moved[i] != 0.0;
    }
  }
  EXPECT_GT(coupled, 10);  // free entries next to constrained ones were tested
}

// No loads (null) is a zero load array, bit for bit.
TEST(Stiffness, EliminatedRightHandSideWithoutLoadsIsThatOfZeroLoads) {
  const Kernels t;
  const TissueModel& m = t.s.model;
  const NodeMat zero = NodeMat::Zero(m.n, 3);
  NodeMat with_zero(m.n, 3), without(m.n, 3);
  std::vector<std::uint8_t> scratch;
  eliminate_rhs(m.pattern, t.s.k, t.s.mask, &zero, t.u_fixed, with_zero, scratch);
  without.setConstant(7.0);
  eliminate_rhs(m.pattern, t.s.k, t.s.mask, nullptr, t.u_fixed, without, scratch);
  EXPECT_EQ(std::memcmp(with_zero.data(), without.data(), sizeof(double) * size_t(without.size())), 0);
  EXPECT_GT(without.cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace vdm
