#include "engine/membrane_strain.hpp"

#include <algorithm>
#include <cmath>

#include "engine/simd4.hpp"

namespace vdm {

std::vector<double> membrane_frames(const SurfaceMesh& rest) {
  const size_t blocks = (size_t(rest.triangle_count()) + 3) / 4;
  std::vector<double> out(blocks * kMembraneFrameBlock, 0.0);  // padding lanes: area 0
  for (int t = 0; t < rest.triangle_count(); ++t) {
    const Vec3 a = rest.positions.row(rest.triangles(t, 0)), b = rest.positions.row(rest.triangles(t, 1)),
               c = rest.positions.row(rest.triangles(t, 2));
    const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
    double* f = out.data() + size_t(t / 4) * kMembraneFrameBlock + size_t(t % 4);  // field k at f[4 k]
    const double area2 = n.norm();
    if (!(area2 > 0.0) || !(ab.norm() > 0.0)) continue;  // degenerate: no strain (the mesh check refuses these)
    const Vec3 e1 = ab.normalized(), e2 = n.cross(ab).normalized();
    // D in the basis: columns (ab.e1, ab.e2) = (|ab|, 0) and (ac.e1, ac.e2); D⁻¹ is upper
    // triangular too.
    const double d00 = ab.dot(e1), d01 = ac.dot(e1), d11 = ac.dot(e2);
    const double det = d00 * d11;
    for (int k = 0; k < 3; ++k) {
      f[4 * k] = e1[k];
      f[4 * (3 + k)] = e2[k];
    }
    f[4 * 6] = d11 / det;
    f[4 * 7] = -d01 / det;
    f[4 * 8] = d00 / det;
    f[4 * 9] = 0.5 * area2;
  }
  return out;
}

Vec membrane_inverse_areas(const SurfaceMesh& rest, const std::vector<double>& frames) {
  Vec area = Vec::Zero(rest.positions.rows());
  for (int t = 0; t < rest.triangle_count(); ++t)
    for (int j = 0; j < 3; ++j)
      area[rest.triangles(t, j)] += frames[size_t(t / 4) * kMembraneFrameBlock + 4 * 9 + size_t(t % 4)];
  for (Eigen::Index i = 0; i < area.size(); ++i) area[i] = area[i] > 0.0 ? 1.0 / area[i] : 0.0;
  return area;
}

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
inline void add_to_corners(const int* tri, const double e[3], double* acc) {
  for (int j = 0; j < 3; ++j) {
    double* p = acc + 3 * size_t(tri[j]);
    p[0] += e[0], p[1] += e[1], p[2] += e[2];
  }
}

// Blocks [0, blocks) of four triangles, four lanes at once.
VDM_AVX2 void strain_blocks_avx2(const double* frames, const int* tris, int count, const double* const u[3],
                                 double* acc) {
  using simd::V4;
  for (int q = 0; 4 * q < count; ++q) {
    const double* f = frames + size_t(q) * kMembraneFrameBlock;
    const int* t = tris + 12 * size_t(q);
    const int lanes = std::min(4, count - 4 * q);
    int ia[4] = {0, 0, 0, 0}, ib[4] = {0, 0, 0, 0}, ic[4] = {0, 0, 0, 0};
    for (int l = 0; l < lanes; ++l) ia[l] = t[3 * l], ib[l] = t[3 * l + 1], ic[l] = t[3 * l + 2];
    const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ia));
    const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ib));
    const __m128i vc = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ic));
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
    double el[3][4];
    for (int d = 0; d < 3; ++d) _mm256_storeu_pd(el[d], e[d]);
    for (int l = 0; l < lanes; ++l) {
      const double et[3] = {el[0][l], el[1][l], el[2][l]};
      add_to_corners(t + 3 * l, et, acc);
    }
  }
}

// The area-weighted sums of E_dd (acc, 3 N, node-major) at the displacement u: the frames four
// triangles at a time (with AVX2 the arithmetic too), the sums added triangle by triangle.
// With the stress effect this runs every step.
void accumulate_strain(const TissueModel& m, const NodeMat& u, double* acc) {
  std::fill(acc, acc + 3 * size_t(m.n), 0.0);
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
    for (int d = 0; d < 3; ++d) strain_dd(i, d) = acc[3 * size_t(i) + size_t(d)] * inv_area[i];
}

void add_membrane_stress(const TissueModel& m, SimState& s, double* scratch) {
  double* acc = scratch;
  accumulate_strain(m, s.u, acc);
  const double* inv_area = m.membrane_inverse_areas.data();
  const double bc = m.connectivity_modulus;
  for (int d = 0; d < 3; ++d) {
    double* stress = s.stress.col(d).data();
    for (int i = 0; i < m.n; ++i) stress[i] += bc * (acc[3 * size_t(i) + size_t(d)] * inv_area[i]);
  }
}

}  // namespace vdm
