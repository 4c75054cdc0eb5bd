#pragma once
// Quantiles of a sample (timings of the benchmark and the accuracy study).
#include <algorithm>
#include <cmath>
#include <vector>

namespace vdmsim {

// The q-quantile (0 <= q <= 1) of `v`, interpolated linearly between order statistics;
// 0 for an empty sample.
inline double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos)), hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace vdmsim
