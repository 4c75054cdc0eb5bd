// The edge-weight kernels of the stiffness against the assembled sparse matrices: the
// product K X per axis, and the eliminated right-hand side (constrained values moved to the
// right, identity rows) against the same elimination done with the full matrix.
#include <gtest/gtest.h>
#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

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
        // Constrained values, zero at every third node (as held entries are: they move nothing).
        if (s.mask(i, d) && i % 3 != 0) u_fixed(i, d) = 1e-3 * (1.0 + std::sin(0.7 * i + d));
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
  eliminate_rhs(m.neighbours, t.s.k, t.s.mask, &t.f, t.u_fixed, rhs);
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
  eliminate_rhs(m.neighbours, t.s.k, t.s.mask, &zero, t.u_fixed, with_zero);
  without.setConstant(7.0);
  eliminate_rhs(m.neighbours, t.s.k, t.s.mask, nullptr, t.u_fixed, without);
  EXPECT_EQ(std::memcmp(with_zero.data(), without.data(), sizeof(double) * size_t(without.size())), 0);
  EXPECT_GT(without.cwiseAbs().maxCoeff(), 0.0);
}

// The constrained entries as lists (held: value zero; prescribed) give the mask's scan's
// right-hand side bit for bit, with loads and without.
TEST(Stiffness, EliminatedRightHandSideFromEntryListsIsTheMasksBitForBit) {
  const Kernels t;
  const TissueModel& m = t.s.model;
  std::vector<int> held, prescribed;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i)
      if (t.s.mask(i, d)) (i % 3 == 0 ? held : prescribed).push_back(d * m.n + i);
  ASSERT_FALSE(held.empty());
  ASSERT_FALSE(prescribed.empty());
  for (const NodeMat* f : {&t.f, static_cast<const NodeMat*>(nullptr)}) {
    NodeMat by_mask(m.n, 3), by_lists(m.n, 3);
    eliminate_rhs(m.neighbours, t.s.k, t.s.mask, f, t.u_fixed, by_mask);
    by_lists.setConstant(7.0);
    eliminate_rhs(m.neighbours, t.s.k, t.s.mask, held, prescribed, f, t.u_fixed, by_lists);
    EXPECT_EQ(std::memcmp(by_mask.data(), by_lists.data(), sizeof(double) * size_t(by_mask.size())), 0);
  }
}

// Without loads, a right-hand side kept from the last call (zero_elsewhere: only the
// prescribed entries and their neighbours rewritten) is the whole array's bit for bit: again
// with the same entries and other weights (a later nonlinear iteration), and with other
// entries once the last ones were cleared (the next step), from a start of NaN everywhere
// but where the first call wrote (the full path zeroes it all).
TEST(Stiffness, EliminatedRightHandSideKeptFromTheLastCallIsTheWholeOnesBitForBit) {
  const Kernels t;
  const TissueModel& m = t.s.model;
  std::vector<int> held, first, second;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      if (!t.s.mask(i, d)) continue;
      if (i % 3 == 0) held.push_back(d * m.n + i);
      else (i % 2 == 0 ? first : second).push_back(d * m.n + i);
    }
  ASSERT_FALSE(first.empty());
  ASSERT_FALSE(second.empty());
  // Masks and values of the two sets of prescribed entries (held ones in both).
  auto masked = [&](const std::vector<int>& prescribed, FlagMat& mask, NodeMat& u) {
    mask = FlagMat::Zero(m.n, 3);
    u = NodeMat::Zero(m.n, 3);
    for (int k : held) mask.data()[k] = 1;
    for (int k : prescribed) {
      mask.data()[k] = 1;
      u.data()[k] = t.u_fixed.data()[k];
    }
  };
  FlagMat mask_a, mask_b;
  NodeMat u_a, u_b;
  masked(first, mask_a, u_a);
  masked(second, mask_b, u_b);
  AxisStiffness other = t.s.k;
  for (Eigen::Index e = 0; e < other.weight.size(); ++e) other.weight[e] *= 1.0 + 0.1 * std::sin(0.3 * double(e));
  NodeMat kept(m.n, 3), whole(m.n, 3);
  kept.setConstant(std::numeric_limits<double>::quiet_NaN());
  eliminate_rhs(m.neighbours, t.s.k, mask_a, held, first, nullptr, u_a, kept, false);
  eliminate_rhs(m.neighbours, t.s.k, mask_a, nullptr, u_a, whole);
  EXPECT_EQ(std::memcmp(kept.data(), whole.data(), sizeof(double) * size_t(whole.size())), 0);
  eliminate_rhs(m.neighbours, other, mask_a, held, first, nullptr, u_a, kept, true);
  eliminate_rhs(m.neighbours, other, mask_a, nullptr, u_a, whole);
  EXPECT_EQ(std::memcmp(kept.data(), whole.data(), sizeof(double) * size_t(whole.size())), 0);
  clear_prescribed_support(m.neighbours, first, kept);
  EXPECT_EQ(kept.cwiseAbs().maxCoeff(), 0.0);
  eliminate_rhs(m.neighbours, t.s.k, mask_b, held, second, nullptr, u_b, kept, true);
  eliminate_rhs(m.neighbours, t.s.k, mask_b, nullptr, u_b, whole);
  EXPECT_EQ(std::memcmp(kept.data(), whole.data(), sizeof(double) * size_t(whole.size())), 0);
  EXPECT_GT(whole.cwiseAbs().maxCoeff(), 0.0);
}

// The edge weights without a division, w_ij = (B_ij / (2 scale)) (|A_i| + |A_j|), and the
// diagonals, against eq (3)-(4) as written (w_ij = B_ij a_ij^2 / V_ij), with no node floored
// and with some (their edges by the plain formula): the same to round-off.
TEST(Stiffness, DivisionFreeWeightsAreThePlainFormula) {
  const axis_test::System sys = axis_test::make_system(CapsuleForm::paper);
  TissueModel m = sys.model;
  m.axis_stiffness_floor = 0.1;  // the diagonals' floor term too
  NodeMat a(m.n, 3);
  distributed_area_vectors(m.rest.positions, m.rest.triangles, a);
  const Vec norms = a.rowwise().norm();
  const double volume = enclosed_volume(m.rest.positions, m.rest.triangles, m.origin);
  for (double min_fraction : {1e-9, 1.0}) {
    Vec v(m.n), scratch(m.n);
    const VolumeScale how = distributed_volumes_from_norms(norms, volume, v, min_fraction);
    EXPECT_EQ(how.any_floored, min_fraction == 1.0);
    AxisStiffness k{Vec(Eigen::Index(m.edges.size())), NodeMat(m.n, 3)};
    assemble_stiffness(m, a, norms, v, how, Vec(), k, scratch);
    Vec lap = Vec::Zero(m.n);
    int floored_edges = 0;
    for (size_t e = 0; e < m.edges.size(); ++e) {
      const int i = m.edges[e][0], j = m.edges[e][1];
      const double aij = 0.5 * (norms[i] + norms[j]);
      const double w = m.connectivity_modulus * aij * aij / (0.5 * (v[i] + v[j]));
      EXPECT_NEAR(k.weight[Eigen::Index(e)], w, 1e-14 * w) << "edge " << e;
      floored_edges += how.floored(norms[i]) || how.floored(norms[j]);
      lap[i] += w;
      lap[j] += w;
    }
    EXPECT_EQ(floored_edges > 0, how.any_floored);
    for (int i = 0; i < m.n; ++i)
      for (int d = 0; d < 3; ++d) {
        const double bulk = m.bulk(i, d) * std::max(a(i, d) * a(i, d), m.axis_stiffness_floor * norms[i] * norms[i]) / v[i];
        EXPECT_NEAR(k.diagonal(i, d), lap[i] + bulk, 1e-13 * (lap[i] + bulk)) << "node " << i << " axis " << d;
      }
    // V_i of no known form (the default VolumeScale): every weight by the plain formula.
    AxisStiffness plain{Vec(Eigen::Index(m.edges.size())), NodeMat(m.n, 3)};
    assemble_stiffness(m, a, norms, v, VolumeScale(), Vec(), plain, scratch);
    for (size_t e = 0; e < m.edges.size(); ++e) {
      const Eigen::Index x = Eigen::Index(e);
      EXPECT_NEAR(plain.weight[x], k.weight[x], 1e-14 * k.weight[x]) << "edge " << e;
    }
  }
}

}  // namespace
}  // namespace vdm
