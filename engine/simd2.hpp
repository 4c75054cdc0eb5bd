#pragma once
// Pairs of doubles as one SSE2 register (GCC/Clang vector extension), for the three-axis
// kernels: lane-wise arithmetic, so the results are those of the scalar code bit for bit.
#include <cstring>

namespace vdm::simd {

typedef double V2 __attribute__((vector_size(16)));

inline V2 load2(const double* p) {
  V2 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store2(double* p, V2 v) { std::memcpy(p, &v, sizeof v); }
inline V2 splat(double a) { return V2{a, a}; }

}  // namespace vdm::simd
