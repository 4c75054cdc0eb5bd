#include "engine/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/simd2.hpp"
#include "engine/simd4.hpp"

namespace vdm {

// Each triangle's signed volume against `origin`, 6 V_k = (a - o) . ((b - o) x (c - o)), is
// computed as (a - o) . ((b - a) x (c - a)) (the same: the terms a x b and c x a are
// perpendicular to a), whose cross product is the one the area vectors need.
double enclosed_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin) {
  double six_v = 0.0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const Vec3 a = x.row(tris(k, 0)).transpose();
    const Vec3 b = x.row(tris(k, 1)).transpose();
    const Vec3 c = x.row(tris(k, 2)).transpose();
    six_v += (a - origin).dot((b - a).cross(c - a));
  }
  return six_v / 6.0;
}

double surface_area(const NodeMat& x, const TriMat& tris) {
  double area = 0.0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const Vec3 a = x.row(tris(k, 0));
    const Vec3 b = x.row(tris(k, 1));
    const Vec3 c = x.row(tris(k, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// A_i = sum over the triangles k at node i of S_k / 3, S_k = (b - a) x (c - a) / 2: the cross
// products are summed per node and scaled by 1/6 once (a division per triangle corner cost
// as much as the rest of the pass).
constexpr double kSixth = 1.0 / 6.0;

void distributed_area_vectors(const NodeMat& x, const TriMat& tris, NodeMat& area_vectors) {
  area_vectors.setZero();
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const int ia = tris(k, 0), ib = tris(k, 1), ic = tris(k, 2);
    const Vec3 a = x.row(ia);
    const Vec3 s = (Vec3(x.row(ib)) - a).cross(Vec3(x.row(ic)) - a);  // 6 S_k / 3
    area_vectors.row(ia) += s.transpose();
    area_vectors.row(ib) += s.transpose();
    area_vectors.row(ic) += s.transpose();
  }
  area_vectors *= kSixth;
}

namespace {

using simd::V2;

// Two nodes' positions (i, i + 1) from the columns of x as the three pairs of their packed rows:
// {x0, y0}, {z0, x1}, {y1, z1}.
struct TwoRows {
  V2 u, v, w;
};
inline TwoRows two_rows(const double* const c[3], size_t i) {
  const V2 x = simd::load2(c[0] + i), y = simd::load2(c[1] + i), z = simd::load2(c[2] + i);
  return {simd::low_pair(x, y), simd::low_from(x, z), simd::high_pair(y, z)};
}

// A triangle's corners a, b, c: their rows of `packed`'s positions (px), whose sums are `3 N` further.
struct Corners {
  double *a, *b, *c;
};
inline Corners corners(double* px, const int* t) {
  return {px + 3 * size_t(t[0]), px + 3 * size_t(t[1]), px + 3 * size_t(t[2])};
}

// Two triangles' cross products s = (b - a) x (c - a) (components x, y, z) and 6 V_k = (a - o) . s,
// the first triangle in lane 0, the second in lane 1. Lane-wise, each lane does the operations
// of the one-triangle formula in the same order (Eigen's cross product, and its 3-vector dot
// (x x' + y y') + z z'), so its bits.
struct TwoCrosses {
  V2 sx, sy, sz, six_v;
};
inline TwoCrosses two_crosses(const Corners& t0, const Corners& t1, const V2 o[3]) {
  const double *a0 = t0.a, *b0 = t0.b, *c0 = t0.c;
  const double *a1 = t1.a, *b1 = t1.b, *c1 = t1.c;
  const V2 ax = simd::pair(a0, a1), ay = simd::pair(a0 + 1, a1 + 1), az = simd::pair(a0 + 2, a1 + 2);
  const V2 ux = simd::pair(b0, b1) - ax, uy = simd::pair(b0 + 1, b1 + 1) - ay, uz = simd::pair(b0 + 2, b1 + 2) - az;
  const V2 vx = simd::pair(c0, c1) - ax, vy = simd::pair(c0 + 1, c1 + 1) - ay, vz = simd::pair(c0 + 2, c1 + 2) - az;
  TwoCrosses r;
  r.sx = uy * vz - uz * vy;
  r.sy = uz * vx - ux * vz;
  r.sz = ux * vy - uy * vx;
  r.six_v = ((ax - o[0]) * r.sx + (ay - o[1]) * r.sy) + (az - o[2]) * r.sz;
  return r;
}

// A triangle's cross product {s_x, s_y}, s_z added to the sums of its corners (`to_sums` = 3 N
// after their positions), a, b, c in turn.
inline void add_to_corners(const Corners& t, size_t to_sums, V2 sxy, double sz) {
  for (double* row : {t.a, t.b, t.c}) {
    double* p = row + to_sums;
    simd::store2(p, simd::load2(p) + sxy);
    p[2] += sz;
  }
}

// Four triangles' corners of one kind (a, b or c: the rows p0 to p3 of triangles 0 to 3) as the
// fours of their coordinates: {x, y} of triangles 0, 2 and of 1, 3 (a 128-bit half each) regrouped
// by lane, and z likewise from {y, z} (no read beyond a row). {p, q} as one four: two_pairs().
struct FourPoints {
  simd::V4 x, y, z;
};
VDM_AVX2 inline simd::V4 two_pairs(const double* p, const double* q) {
  return _mm256_insertf128_pd(_mm256_castpd128_pd256(simd::load2(p)), simd::load2(q), 1);
}
VDM_AVX2 inline FourPoints four_points(const double* p0, const double* p1, const double* p2, const double* p3) {
  const simd::V4 xy02 = two_pairs(p0, p2), xy13 = two_pairs(p1, p3);
  const simd::V4 yz02 = two_pairs(p0 + 1, p2 + 1), yz13 = two_pairs(p1 + 1, p3 + 1);
  return {_mm256_unpacklo_pd(xy02, xy13), _mm256_unpackhi_pd(xy02, xy13), _mm256_unpackhi_pd(yz02, yz13)};
}

// Four triangles at a time (from `t` to `end`, whole fours) for the cross products and the volume
// terms, lane-wise the operations of two_crosses() in the same order (AVX2 without FMA: the same
// bits); the sums added triangle by triangle in order (add_to_corners()), the volume terms added
// to `six_v` in triangle order. Returns the new six_v.
VDM_AVX2 double four_triangle_pass(const double* px, double* pa, const int* t, const int* end, const double* origin,
                                   double six_v) {
  using simd::V2;
  using simd::V4;
  const V4 ox = simd::splat4(origin[0]), oy = simd::splat4(origin[1]), oz = simd::splat4(origin[2]);
  // A corner's sums, a's, b's and c's in turn (the row offset 3 i from t again: the twelve rows
  // need not stay in registers across the arithmetic).
  const auto add = [pa](const int* tri, V2 sxy, double sz) {
    for (int j = 0; j < 3; ++j) {
      double* p = pa + 3 * size_t(tri[j]);
      simd::store2(p, simd::load2(p) + sxy);
      p[2] += sz;
    }
  };
  for (; t != end; t += 12) {
    const auto row = [px, t](int j) { return px + 3 * size_t(t[j]); };
    const FourPoints a = four_points(row(0), row(3), row(6), row(9));
    const FourPoints b = four_points(row(1), row(4), row(7), row(10));
    const FourPoints c = four_points(row(2), row(5), row(8), row(11));
    const V4 ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    const V4 vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
    const V4 sx = uy * vz - uz * vy;
    const V4 sy = uz * vx - ux * vz;
    const V4 sz = ux * vy - uy * vx;
    const V4 v6 = ((a.x - ox) * sx + (a.y - oy) * sy) + (a.z - oz) * sz;
    const V4 xy02 = _mm256_unpacklo_pd(sx, sy), xy13 = _mm256_unpackhi_pd(sx, sy);  // {sx, sy} of 0, 2 and 1, 3
    const V2 z01 = simd::low2(sz), z23 = _mm256_extractf128_pd(sz, 1);
    add(t, simd::low2(xy02), z01[0]);
    add(t + 3, simd::low2(xy13), z01[1]);
    add(t + 6, _mm256_extractf128_pd(xy02, 1), z23[0]);
    add(t + 9, _mm256_extractf128_pd(xy13, 1), z23[1]);
    six_v += v6[0];
    six_v += v6[1];
    six_v += v6[2];
    six_v += v6[3];
  }
  return six_v;
}

}  // namespace

// Two triangles at a time for the arithmetic (four with AVX2, the rest two at a time), their sums
// added triangle by triangle in order and the volume terms summed in triangle order: every sum is
// the one-triangle loop's, term for term.
double packed_area_sums_and_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin,
                                   std::vector<double>& packed) {
  const size_t n = size_t(x.rows());
  packed.resize(6 * n);
  double* px = packed.data();
  double* pa = px + 3 * n;
  const double* const col[3] = {x.col(0).data(), x.col(1).data(), x.col(2).data()};
  // Positions row by row and zero sums, two nodes at a time.
  const V2 zero = {0.0, 0.0};
  size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const TwoRows r = two_rows(col, i);
    double *p = px + 3 * i, *q = pa + 3 * i;
    simd::store2(p, r.u);
    simd::store2(p + 2, r.v);
    simd::store2(p + 4, r.w);
    simd::store2(q, zero);
    simd::store2(q + 2, zero);
    simd::store2(q + 4, zero);
  }
  for (; i < n; ++i)
    for (size_t d = 0; d < 3; ++d) {
      px[3 * i + d] = col[d][i];
      pa[3 * i + d] = 0.0;
    }
  const V2 o[3] = {simd::splat(origin.x()), simd::splat(origin.y()), simd::splat(origin.z())};
  const int* t = tris.data();  // row-major: a triangle's three indices together
  const int* const pairs_end = t + 6 * (size_t(tris.rows()) / 2);
  double six_v = 0.0;
  if (simd::avx2_enabled()) {  // the fours first, then what is left as below
    const int* const fours_end = t + 12 * (size_t(tris.rows()) / 4);
    six_v = four_triangle_pass(px, pa, t, fours_end, origin.data(), six_v);
    t = fours_end;
  }
  for (; t != pairs_end; t += 6) {
    const Corners t0 = corners(px, t), t1 = corners(px, t + 3);
    const TwoCrosses s = two_crosses(t0, t1, o);
    add_to_corners(t0, 3 * n, simd::low_pair(s.sx, s.sy), s.sz[0]);
    add_to_corners(t1, 3 * n, simd::high_pair(s.sx, s.sy), s.sz[1]);
    six_v += s.six_v[0];
    six_v += s.six_v[1];
  }
  if (tris.rows() % 2 != 0) {  // an odd count: the last triangle in both lanes, lane 0's result used
    const Corners t0 = corners(px, t);
    const TwoCrosses s = two_crosses(t0, t0, o);
    add_to_corners(t0, 3 * n, simd::low_pair(s.sx, s.sy), s.sz[0]);
    six_v += s.six_v[0];
  }
  return six_v / 6.0;
}

void unpack_area_vectors(const std::vector<double>& packed, NodeMat& area_vectors) {
  const size_t n = size_t(area_vectors.rows());
  const double* pa = packed.data() + 3 * n;
  for (size_t d = 0; d < 3; ++d) {
    double* col = area_vectors.col(Eigen::Index(d)).data();
    for (size_t i = 0; i < n; ++i) col[i] = pa[3 * i + d] * kSixth;
  }
}

namespace {

// unpack_area_vectors_and_norms()'s nodes 0 to `end` (a multiple of 4) four at a time: the
// low 128-bit halves hold the two-node loop's pair (i, i + 1), the high ones its pair
// (i + 2, i + 3), each regrouped as that loop regroups a pair; the lengths added to and compared with `total` and `smallest`
// pair by pair in node order, so the same bits as that loop.
VDM_AVX2 void unpack_four_nodes(const double* pa, double* const c[3], double* norm, size_t end, simd::V2& total,
                                simd::V2& smallest) {
  using simd::V4;
  const V4 sixth = simd::splat4(kSixth);
  double *const cx = c[0], *const cy = c[1], *const cz = c[2];
  simd::V2 t = total, m = smallest;  // in registers (the caller's may alias the outputs)
  for (size_t i = 0; i < end; i += 4) {
    const double* p = pa + 3 * i;
    const V4 u = two_pairs(p, p + 6), v = two_pairs(p + 2, p + 8), w = two_pairs(p + 4, p + 10);
    const V4 x = V4(_mm256_shuffle_pd(u, v, 0xA)) * sixth, y = V4(_mm256_shuffle_pd(u, w, 0x5)) * sixth,
             z = V4(_mm256_shuffle_pd(v, w, 0xA)) * sixth;
    simd::store4(cx + i, x);
    simd::store4(cy + i, y);
    simd::store4(cz + i, z);
    const V4 length = _mm256_sqrt_pd(x * x + y * y + z * z);
    simd::store4(norm + i, length);
    const simd::V2 first = simd::low2(length), second = _mm256_extractf128_pd(length, 1);
    t += first;
    t += second;
    m = simd::min2(m, first);
    m = simd::min2(m, second);
  }
  total = t;
  smallest = m;
}

}  // namespace

AreaNormSums unpack_area_vectors_and_norms(const std::vector<double>& packed, NodeMat& area_vectors, Vec& area_norms) {
  using simd::V2;
  const size_t n = size_t(area_vectors.rows());
  const double* pa = packed.data() + 3 * n;
  double* c[3] = {area_vectors.col(0).data(), area_vectors.col(1).data(), area_vectors.col(2).data()};
  double* norm = area_norms.data();
  // Two nodes at a time: their six packed sums as three pairs, regrouped by axis (with AVX2,
  // four at a time first).
  const V2 sixth = simd::splat(kSixth);
  V2 total = {0.0, 0.0}, smallest = simd::splat(std::numeric_limits<double>::infinity());
  size_t i = 0;
  if (simd::avx2_enabled()) {
    i = n / 4 * 4;
    unpack_four_nodes(pa, c, norm, i, total, smallest);
  }
  for (; i + 2 <= n; i += 2) {
    const double* p = pa + 3 * i;
    const V2 u = simd::load2(p), v = simd::load2(p + 2), w = simd::load2(p + 4);  // x0 y0, z0 x1, y1 z1
    const V2 x = V2(_mm_shuffle_pd(u, v, 2)) * sixth, y = V2(_mm_shuffle_pd(u, w, 1)) * sixth,
             z = V2(_mm_shuffle_pd(v, w, 2)) * sixth;
    simd::store2(c[0] + i, x);
    simd::store2(c[1] + i, y);
    simd::store2(c[2] + i, z);
    const V2 length = simd::sqrt2(x * x + y * y + z * z);
    simd::store2(norm + i, length);
    total += length;
    smallest = simd::min2(smallest, length);
  }
  AreaNormSums sums{total[0] + total[1], std::min(smallest[0], smallest[1])};
  for (; i < n; ++i) {
    const double x = pa[3 * i] * kSixth, y = pa[3 * i + 1] * kSixth, z = pa[3 * i + 2] * kSixth;
    c[0][i] = x;
    c[1][i] = y;
    c[2][i] = z;
    norm[i] = std::sqrt(x * x + y * y + z * z);
    sums.total += norm[i];
    sums.smallest = std::min(sums.smallest, norm[i]);
  }
  return sums;
}

bool packed_positions_equal(const NodeMat& x, const std::vector<double>& packed) {
  const size_t n = size_t(x.rows());
  if (packed.size() != 6 * n) return false;
  // Bits, not values (-0 and 0, NaNs): the same bits give the same sums. Two nodes at a time,
  // their columns regrouped as their packed rows, the differences OR-ed over a block of nodes
  // before the branch.
  const double* const c[3] = {x.col(0).data(), x.col(1).data(), x.col(2).data()};
  const double* p = packed.data();
  constexpr size_t kBlock = 64;  // even: only the last block has a node alone
  for (size_t i0 = 0; i0 < n; i0 += kBlock) {
    V2 diff = {0.0, 0.0};
    const size_t end = std::min(n, i0 + kBlock);
    size_t i = i0;
    for (; i + 2 <= end; i += 2) {
      const TwoRows r = two_rows(c, i);
      const double* q = p + 3 * i;
      diff = simd::or2(diff, simd::or2(simd::or2(simd::xor2(simd::load2(q), r.u), simd::xor2(simd::load2(q + 2), r.v)),
                                       simd::xor2(simd::load2(q + 4), r.w)));
    }
    if (i < end) {  // the last node of an odd count
      const V2 xy = {c[0][i], c[1][i]}, z = {c[2][i], 0.0}, qz = {p[3 * i + 2], 0.0};
      diff = simd::or2(diff, simd::or2(simd::xor2(simd::load2(p + 3 * i), xy), simd::xor2(qz, z)));
    }
    if (!simd::all_bits_zero(diff)) return false;
  }
  return true;
}

double area_vectors_and_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin, NodeMat& area_vectors,
                               std::vector<double>& packed) {
  const double v = packed_area_sums_and_volume(x, tris, origin, packed);
  unpack_area_vectors(packed, area_vectors);
  return v;
}

VolumeScale distributed_volumes(const NodeMat& area_vectors, double volume, Vec& volumes, double min_fraction) {
  const Eigen::Index n = area_vectors.rows();
  Vec norms(n);
  for (Eigen::Index i = 0; i < n; ++i) norms[i] = area_vectors.row(i).norm();
  return distributed_volumes_from_norms(norms, volume, volumes, min_fraction);
}

VolumeScale distributed_volumes_from_norms(const Vec& area_norms, double volume, Vec& volumes, double min_fraction) {
  AreaNormSums sums;
  for (Eigen::Index i = 0; i < area_norms.size(); ++i) {
    sums.total += area_norms[i];
    sums.smallest = std::min(sums.smallest, area_norms[i]);
  }
  return distributed_volumes_from_norms(area_norms, sums, volume, volumes, min_fraction);
}

VolumeScale distributed_volumes_from_norms(const Vec& area_norms, const AreaNormSums& sums, double volume,
                                           Vec& volumes, double min_fraction) {
  const Eigen::Index n = area_norms.size();
  VolumeScale how;
  how.floor_area = min_fraction * sums.total / double(std::max<Eigen::Index>(n, 1));
  how.any_floored = how.floored(sums.smallest);
  // Without a floored node (nearly always) the floored areas' sum is the areas' own.
  double floored_total = sums.total;
  if (how.any_floored) {
    floored_total = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) floored_total += std::max(area_norms[i], how.floor_area);
  }
  how.scale = floored_total > 0.0 ? volume / floored_total : 0.0;
  for (Eigen::Index i = 0; i < n; ++i) volumes[i] = how.scale * std::max(area_norms[i], how.floor_area);
  return how;
}

int nearest_node(const NodeMat& x, const Vec3& p) {
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double di = (x.row(i).transpose() - p).squaredNorm();
    if (di < d) {
      d = di;
      best = static_cast<int>(i);
    }
  }
  return best;
}

Vec3 closest_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Regions of the triangle's plane (vertex, edge, face), after Ericson's Real-Time Collision
  // Detection, section 5.1.5.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

}  // namespace vdm
