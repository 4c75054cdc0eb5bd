#include "engine/membrane_strain.hpp"

#include <algorithm>
#include <cmath>

#include "engine/simd4.hpp"

namespace vdm {

namespace {

// One triangle's area-weighted strain diagonal e (3) from its corners' displacement
// differences ab, ac and its frame's fields f (kMembraneFrameFields); T is double (one triangle) or
// simd::V4 (four, one per lane: the same operations in the same order, so the same bits; AVX2
// without FMA cannot contract).
// The displacement's gradient in the rest plane, H = [u_ab u_ac] D⁻¹ (3 x 2), so F = P + H
// with P = [e1 e2], and E = ½ (Pᵀ H + Hᵀ P + Hᵀ H): exactly zero at rest, no cancellation;
// E3_dd = Σ_pq P_dp E_pq P_dq, times the area.
template <typename T>
inline void triangle_strain(const T ab[3], const T ac[3], const T f[kMembraneFrameFields], T e[3]) {
  const T i00 = f[6], i01 = f[7], i11 = f[8];  // D⁻¹ (its entry (1,0) is zero)
  const T h0x = ab[0] * i00, h0y = ab[1] * i00, h0z = ab[2] * i00;
  const T h1x = ab[0] * i01 + ac[0] * i11, h1y = ab[1] * i01 + ac[1] * i11, h1z = ab[2] * i01 + ac[2] * i11;
  const T e1x = f[0], e1y = f[1], e1z = f[2], e2x = f[3], e2y = f[4], e2z = f[5];
  const T half = T{} + 0.5, two = T{} + 2.0;
  const T E00 = e1x * h0x + e1y * h0y + e1z * h0z + half * (h0x * h0x + h0y * h0y + h0z * h0z);
  const T E11 = e2x * h1x + e2y * h1y + e2z * h1z + half * (h1x * h1x + h1y * h1y + h1z * h1z);
  const T E01 = half * (e1x * h1x + e1y * h1y + e1z * h1z + e2x * h0x + e2y * h0y + e2z * h0z + h0x * h1x + h0y * h1y +
                        h0z * h1z);
  const T area = f[9];
  const T a00 = area * E00, a01 = two * area * E01, a11 = area * E11;
  e[0] = e1x * e1x * a00 + e1x * e2x * a01 + e2x * e2x * a11;
  e[1] = e1y * e1y * a00 + e1y * e2y * a01 + e2y * e2y * a11;
  e[2] = e1z * e1z * a00 + e1z * e2z * a01 + e2z * e2z * a11;
}

// Triangle t's e added to its corners (triangle order: the sums are the same in both paths).
// acc: 4 per node (the fourth unused), so that the AVX2 path adds a triangle's three as one
// vector.
inline void add_to_corners(const int* tri, const double e[3], double* acc) {
  for (int j = 0; j < 3; ++j) {
    double* p = acc + 4 * size_t(tri[j]);
    p[0] += e[0], p[1] += e[1], p[2] += e[2];
  }
}

// The corners of triangles 4q .. 4q + 3 (row-major, 12 ints from t) as the vectors
// (a0 a1 a2 a3), (b0 ...), (c0 ...): three loads and a shuffle each, where building them in
// memory int by int stalled every block on the 128-bit load of what was just stored.
VDM_AVX2 inline void block_corners(const int* t, __m128i& a, __m128i& b, __m128i& c) {
  const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t));      // a0 b0 c0 a1
  const __m128i y = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t + 4));  // b1 c1 a2 b2
  const __m128i z = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t + 8));  // c2 a3 b3 c3
  a = _mm_shuffle_epi32(_mm_blend_epi32(_mm_blend_epi32(x, y, 0x4), z, 0x2), _MM_SHUFFLE(1, 2, 3, 0));
  b = _mm_shuffle_epi32(_mm_blend_epi32(_mm_blend_epi32(x, y, 0x9), z, 0x4), _MM_SHUFFLE(2, 3, 0, 1));
  c = _mm_shuffle_epi32(_mm_blend_epi32(_mm_blend_epi32(x, y, 0x2), z, 0x9), _MM_SHUFFLE(3, 0, 1, 2));
}

// Blocks [0, blocks) of four triangles, four lanes at once.
VDM_AVX2 void strain_blocks_avx2(const double* frames, const int* tris, int count, const double* const u[3],
                                 double* acc) {
  using simd::V4;
  for (int q = 0; 4 * q < count; ++q) {
    const double* f = frames + size_t(q) * kMembraneFrameBlock;
    const int* t = tris + 12 * size_t(q);
    const int lanes = std::min(4, count - 4 * q);
    __m128i va, vb, vc;
    if (lanes == 4) {
      block_corners(t, va, vb, vc);
    } else {  // the last, partial block: its padding lanes read node 0 (their area is 0)
      int last[12] = {};
      std::copy(t, t + 3 * lanes, last);
      block_corners(last, va, vb, vc);
    }
    V4 ab[3], ac[3];
    const __m256d zero = _mm256_setzero_pd(), all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    for (int d = 0; d < 3; ++d) {
      const V4 ua = _mm256_mask_i32gather_pd(zero, u[d], va, all, 8);
      ab[d] = V4(_mm256_mask_i32gather_pd(zero, u[d], vb, all, 8)) - ua;
      ac[d] = V4(_mm256_mask_i32gather_pd(zero, u[d], vc, all, 8)) - ua;
    }
    V4 fields[kMembraneFrameFields], e[3];
    for (int k = 0; k < kMembraneFrameFields; ++k) fields[k] = simd::load4(f + 4 * k);
    triangle_strain<V4>(ab, ac, fields, e);
    // Lane l's (e_x, e_y, e_z, 0), added to each of its corners' four sums at once.
    const __m256d lo_xy = _mm256_unpacklo_pd(e[0], e[1]), hi_xy = _mm256_unpackhi_pd(e[0], e[1]);
    const __m256d lo_z = _mm256_unpacklo_pd(e[2], zero), hi_z = _mm256_unpackhi_pd(e[2], zero);
    const __m256d per_lane[4] = {_mm256_permute2f128_pd(lo_xy, lo_z, 0x20), _mm256_permute2f128_pd(hi_xy, hi_z, 0x20),
                                 _mm256_permute2f128_pd(lo_xy, lo_z, 0x31), _mm256_permute2f128_pd(hi_xy, hi_z, 0x31)};
    for (int l = 0; l < lanes; ++l)
      for (int j = 0; j < 3; ++j) {
        double* p = acc + 4 * size_t(t[3 * l + j]);
        _mm256_storeu_pd(p, _mm256_add_pd(_mm256_loadu_pd(p), per_lane[l]));
      }
  }
}

// The area-weighted sums of E_dd (acc, 4 N, node-major, the fourth of each node's unused) at
// the displacement u: the frames four triangles at a time (with AVX2 the arithmetic too), the
// sums added triangle by triangle. With the stress effect this runs every step.
void accumulate_strain(const TissueModel& m, const NodeMat& u, double* acc) {
  std::fill(acc, acc + 4 * size_t(m.n), 0.0);
  const int* tris = m.rest.triangles.data();  // row-major
  const int count = int(m.rest.triangles.rows());
  const double* const uc[3] = {u.col(0).data(), u.col(1).data(), u.col(2).data()};
  const double* frames = m.membrane_frames.data();
  if (simd::avx2_enabled()) {
    strain_blocks_avx2(frames, tris, count, uc, acc);
    return;
  }
  for (int t = 0; t < count; ++t) {
    const double* f = frames + size_t(t / 4) * kMembraneFrameBlock + size_t(t % 4);
    const int* tri = tris + 3 * size_t(t);
    const int a = tri[0], b = tri[1], c = tri[2];
    double ab[3], ac[3], e[3], fields[kMembraneFrameFields];
    for (int d = 0; d < 3; ++d) {
      ab[d] = uc[d][b] - uc[d][a];
      ac[d] = uc[d][c] - uc[d][a];
    }
    for (int k = 0; k < kMembraneFrameFields; ++k) fields[k] = f[4 * k];
    triangle_strain<double>(ab, ac, fields, e);
    add_to_corners(tri, e, acc);
  }
}

}  // namespace

void membrane_axis_strain(const TissueModel& m, const NodeMat& u, NodeMat& strain_dd, double* scratch) {
  double* acc = scratch;
  accumulate_strain(m, u, acc);
  const double* inv_area = m.membrane_inverse_areas.data();
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) strain_dd(i, d) = acc[4 * size_t(i) + size_t(d)] * inv_area[i];
}

void add_membrane_stress(const TissueModel& m, SimState& s, double* scratch) {
  double* acc = scratch;
  accumulate_strain(m, s.u, acc);
  const double* inv_area = m.membrane_inverse_areas.data();
  const double bc = m.connectivity_modulus;
  for (int d = 0; d < 3; ++d) {
    double* stress = s.stress.col(d).data();
    for (int i = 0; i < m.n; ++i) stress[i] += bc * (acc[4 * size_t(i) + size_t(d)] * inv_area[i]);
  }
}

}  // namespace vdm
