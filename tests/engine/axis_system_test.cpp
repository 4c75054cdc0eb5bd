// What every solver takes of an AxisSystem: the eliminated matrices' mean diagonal and the
// free area vectors, against the plain sums over the entries.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/linear_solver.hpp"
#include "support/axis_systems.hpp"

namespace vdm {
namespace {

// The test system's mask holds a cap on every axis and a band on y only: blocks of entries
// with and without constrained ones; 3 N = 1926 is no multiple of 16 (the last entries alone).
TEST(AxisSystem, MeanDiagonalAndFreeAreaVectorsAreThePlainSums) {
  const axis_test::System s = axis_test::make_system();
  const TissueModel& m = s.model;
  ASSERT_NE(3 * m.n % 16, 0);
  NodeMat a(m.n, 3), springs = NodeMat::Zero(m.n, 3);
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) {
      a(i, d) = std::sin(0.37 * i - 1.1 * d);
      if (i % 5 == 0) springs(i, d) = 50.0 * (1.0 + std::cos(0.2 * i + d));
    }
  for (const bool with_springs : {false, true}) {
    const AxisSystem system{&s.k, &m.pattern, &s.mask, with_springs ? &springs : nullptr};
    NodeMat a_free = NodeMat::Constant(m.n, 3, 7.0);
    const double mean = eliminated_mean_diagonal(system, &a, &a_free);
    double sum = 0.0;
    int constrained = 0;
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i) {
        const bool c = s.mask(i, d) != 0;
        constrained += c;
        sum += c ? 1.0 : std::abs(s.k.diagonal(i, d) + (with_springs ? springs(i, d) : 0.0));
        EXPECT_EQ(a_free(i, d), c ? 0.0 : a(i, d)) << "node " << i << " axis " << d;
      }
    EXPECT_GT(constrained, 20);
    const double plain = sum / (3.0 * m.n);
    EXPECT_NEAR(mean, plain, 1e-14 * plain) << "springs " << with_springs;
    EXPECT_EQ(eliminated_mean_diagonal(system), mean);  // the same without the area vectors
  }
}

}  // namespace
}  // namespace vdm
