#include "engine/node_sums.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "engine/types.hpp"

namespace vdm {
namespace {

// NodeSums over the products a_i b_i, fed as finish() in the structured solver feeds it
// (four at a time, then a pair, then one), against Eigen's dot product: the same bits.
double node_sum_dot(const Vec& a, const Vec& b) {
  NodeSums sum;
  const int n = int(a.size());
  auto pair = [&](int i) { return simd::load2(a.data() + i) * simd::V2{b[i], b[i + 1]}; };
  int i = 0;
  for (; i + 4 <= n; i += 4) sum.add4(pair(i), pair(i + 2));
  if (i + 2 <= n) {
    sum.add2(pair(i));
    i += 2;
  }
  if (i < n) sum.add1(a[i] * b[i]);
  return sum.total();
}

TEST(NodeSums, DotProductsInEigensOrderBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> scale(-30, 30);
  for (int n = 0; n <= 70; ++n)
    for (int trial = 0; trial < 20; ++trial) {
      Vec a(n), b(n);
      for (int i = 0; i < n; ++i) {
        a[i] = std::ldexp(u(rng), scale(rng));
        b[i] = std::ldexp(u(rng), scale(rng));
      }
      const double expected = a.dot(b), got = node_sum_dot(a, b);
      EXPECT_EQ(std::memcmp(&expected, &got, sizeof got), 0) << "n " << n << ": " << expected << " vs " << got;
    }
}

TEST(NodeSums, ColumnsOfANodeMatAsEigenDotsThem) {
  // The column of an N x 3 matrix (odd N: columns 1 and 2 not 16-byte aligned).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n : {1, 5, 10242, 2501}) {
    NodeMat a(n, 3), b(n, 3);
    for (Eigen::Index k = 0; k < a.size(); ++k) {
      a.data()[k] = u(rng);
      b.data()[k] = u(rng);
    }
    for (int d = 0; d < 3; ++d) {
      const double expected = a.col(d).dot(b.col(d));
      const double got = node_sum_dot(a.col(d), b.col(d));
      EXPECT_EQ(std::memcmp(&expected, &got, sizeof got), 0) << "n " << n << " axis " << d;
    }
  }
}

}  // namespace
}  // namespace vdm
