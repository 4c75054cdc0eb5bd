#pragma once
// Fours of doubles as one AVX2 register (GCC/Clang vector extension), for the kernels on
// blocks of 6 vectors: a row of 6 is one four-lane vector and one two-lane one (simd2.hpp)
// instead of three two-lane ones. Lane-wise multiplies and adds, never fused (AVX2 without
// FMA: the compiler cannot contract), so the same bits as the SSE2 kernels.
//
// The build stays x86-64 (SSE2) throughout: only functions marked VDM_AVX2 are compiled for
// AVX2, and they run only when avx2_enabled(). The helpers here are VDM_AVX2 themselves:
// call them from VDM_AVX2 functions only.
#include <immintrin.h>

#include <cstring>

#include "engine/simd2.hpp"

#define VDM_AVX2 __attribute__((target("avx2")))

namespace vdm::simd {

typedef double V4 __attribute__((vector_size(32)));

// Unaligned (the blocks' rows are 48 bytes apart: only every other one is 32-byte aligned).
VDM_AVX2 inline V4 load4(const double* p) {
  V4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
VDM_AVX2 inline void store4(double* p, V4 v) { std::memcpy(p, &v, sizeof v); }
VDM_AVX2 inline V4 splat4(double a) { return V4{a, a, a, a}; }
// Lanes 0 and 1 (no instruction).
VDM_AVX2 inline V2 low2(V4 a) { return _mm256_castpd256_pd128(a); }
// {a[0], a[0], a[1], a[1]} (one vpermpd each).
VDM_AVX2 inline V4 dup01(V2 a) { return _mm256_permute4x64_pd(_mm256_castpd128_pd256(a), 0x50); }
VDM_AVX2 inline V4 dup01(V4 a) { return _mm256_permute4x64_pd(a, 0x50); }
// {a[2], a[2]} (one vpermpd).
VDM_AVX2 inline V2 dup2(V4 a) { return low2(_mm256_permute4x64_pd(a, 0xAA)); }
// Four adjacent floats as doubles (one vcvtps2pd from memory; exact).
VDM_AVX2 inline V4 load4f(const float* p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }

// Whether this CPU (and OS) runs AVX2.
bool avx2_supported();
// Whether the kernels take their AVX2 variants: where supported, unless the environment
// variable VDMSIM_SIMD is "sse2" (read once, at the first use) or set_avx2(false) was called.
bool avx2_enabled();
// Chooses the variants from now on (tests compare both); `on` is ignored where AVX2 is not
// supported. Returns avx2_enabled(). Not while a kernel runs on another thread.
bool set_avx2(bool on);

}  // namespace vdm::simd
