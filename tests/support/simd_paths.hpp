#pragma once
// The kernels' SSE2 and AVX2 variants (engine/simd4.hpp) on the same input: run(false)
// then run(true), the choice in force restored afterwards.
#include "engine/simd4.hpp"

namespace vdm::simd_test {

template <class Run>
void sse2_then_avx2(const Run& run) {
  const bool saved = simd::avx2_enabled();
  simd::set_avx2(false);
  run(false);
  simd::set_avx2(true);
  run(true);
  simd::set_avx2(saved);
}

}  // namespace vdm::simd_test
