// The exponent-bit finiteness check agrees with std::isfinite on every kind of value, at
// every position of an array (the vectorised body and its tail).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "engine/all_finite.hpp"

namespace vdm {
namespace {

TEST(AllFinite, AgreesWithIsfiniteAtEveryPosition) {
  const double inf = std::numeric_limits<double>::infinity();
  const double specials[] = {inf, -inf, std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::signaling_NaN()};
  const double finite[] = {0.0, -0.0, 1.0, -3.5e300, std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min()};
  for (size_t n : {1u, 2u, 3u, 7u, 16u, 33u}) {
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = finite[i % (sizeof finite / sizeof finite[0])];
    EXPECT_TRUE(all_finite(v.data(), n)) << n;
    for (size_t at = 0; at < n; ++at)
      for (double s : specials) {
        std::vector<double> w = v;
        w[at] = s;
        EXPECT_FALSE(all_finite(w.data(), n)) << n << " at " << at << ": " << s;
      }
  }
  EXPECT_TRUE(all_finite(nullptr, 0));
  NodeMat m = NodeMat::Constant(5, 3, 2.0);
  EXPECT_TRUE(all_finite(m));
  m(4, 2) = -inf;
  EXPECT_FALSE(all_finite(m));
}

}  // namespace
}  // namespace vdm
