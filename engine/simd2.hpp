#pragma once
// Pairs of doubles as one SSE2 register (GCC/Clang vector extension), for the three-axis
// kernels: lane-wise arithmetic, so the results are those of the scalar code bit for bit.
#include <emmintrin.h>

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
// Two adjacent floats as a pair of doubles (one cvtps2pd from memory; exact).
inline V2 load2f(const float* p) {
  double t;
  std::memcpy(&t, p, sizeof t);
  return _mm_cvtps_pd(_mm_castpd_ps(_mm_set_sd(t)));
}
// {a[0] * b[0], a[1]} (one mulsd: lane 1 of `a` kept as it is).
inline V2 mul_low(V2 a, V2 b) { return _mm_mul_sd(a, b); }
// A compiler barrier on three pairs (no instruction): their values exist here, in registers.
// Keeps an unrolled gather entry after entry instead of grouped by operation with its loads
// hoisted ahead and spilled (what GCC 12 does with a fixed-count gather otherwise).
inline void keep_in_registers(V2& a, V2& b, V2& c) { asm("" : "+x"(a), "+x"(b), "+x"(c)); }
// {a[0], a[0]} and {a[1], a[1]}.
inline V2 splat_low(V2 a) { return _mm_unpacklo_pd(a, a); }
inline V2 splat_high(V2 a) { return _mm_unpackhi_pd(a, a); }
// Lane-wise std::max(a, b): b where a < b, else a (one maxpd).
inline V2 max2(V2 a, V2 b) { return _mm_max_pd(b, a); }
// Lane-wise std::min(a, b): b where b < a, else a (one minpd).
inline V2 min2(V2 a, V2 b) { return _mm_min_pd(b, a); }
inline V2 sqrt2(V2 a) { return _mm_sqrt_pd(a); }
inline V2 abs2(V2 a) { return _mm_andnot_pd(_mm_set1_pd(-0.0), a); }

// {p[0], q[0]}: one double from each of two places (movsd, movhpd).
inline V2 pair(const double* p, const double* q) { return V2{*p, *q}; }
// {a[0], b[0]} and {a[1], b[1]}: two pairs regrouped by lane.
inline V2 low_pair(V2 a, V2 b) { return _mm_unpacklo_pd(a, b); }
inline V2 high_pair(V2 a, V2 b) { return _mm_unpackhi_pd(a, b); }
// {b[0], a[1]} (one movsd).
inline V2 low_from(V2 a, V2 b) { return _mm_move_sd(a, b); }
// Bitwise a ^ b and a | b of two pairs.
inline V2 xor2(V2 a, V2 b) { return _mm_xor_pd(a, b); }
inline V2 or2(V2 a, V2 b) { return _mm_or_pd(a, b); }
// Whether all 128 bits of a are zero.
inline bool all_bits_zero(V2 a) {
  const __m128i b = _mm_castpd_si128(a);
  return _mm_movemask_epi8(_mm_cmpeq_epi8(b, _mm_setzero_si128())) == 0xFFFF;
}

// Whether none of the 16 flags (bytes) from p is set.
inline bool none_set16(const unsigned char* p) {
  const __m128i flags = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  return _mm_movemask_epi8(_mm_cmpeq_epi8(flags, _mm_setzero_si128())) == 0xFFFF;
}

}  // namespace vdm::simd
