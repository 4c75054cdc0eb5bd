#include "engine/axis_matrices.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "engine/simd2.hpp"
#include "engine/simd4.hpp"

namespace vdm {

void AxisMatrices::analyze(const StiffnessPattern& pattern, const std::vector<int>& perm) {
  const SpMat& m = pattern.matrix;
  n = static_cast<int>(m.cols());
  std::vector<int> iperm(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) iperm[size_t(perm.empty() ? i : perm[size_t(i)])] = i;
  // The edge of each of the pattern's value slots (-1: a diagonal).
  std::vector<int> slot_edge(size_t(m.nonZeros()), -1);
  for (size_t e = 0; e < pattern.edge_slot.size(); ++e)
    slot_edge[size_t(pattern.edge_slot[e][0])] = slot_edge[size_t(pattern.edge_slot[e][1])] = int(e);
  const int* outer = m.outerIndexPtr();
  const int* inner = m.innerIndexPtr();
  start.assign(size_t(n) + 1, 0);
  col6.clear();
  off_edge.clear();
  std::vector<std::pair<int, int>> row;  // (column here, edge)
  for (int i = 0; i < n; ++i) {
    const int node = perm.empty() ? i : perm[size_t(i)];
    row.clear();
    bool has_diagonal = false;
    // K is symmetric: row `node` is column `node`.
    for (int k = outer[node]; k < outer[node + 1]; ++k) {
      if (inner[k] == node) {
        has_diagonal = true;
        continue;
      }
      if (slot_edge[size_t(k)] < 0) throw std::invalid_argument("AxisMatrices: an off-diagonal entry without its edge");
      row.emplace_back(iperm[size_t(inner[k])], slot_edge[size_t(k)]);
    }
    if (!has_diagonal) throw std::invalid_argument("AxisMatrices: the pattern lacks a diagonal entry");
    std::sort(row.begin(), row.end());
    for (const auto& e : row) {
      col6.push_back(6 * e.first);
      off_edge.push_back(e.second);
    }
    start[size_t(i) + 1] = static_cast<int>(col6.size());
  }
  off.assign(col6.size(), 0.0);
  diag.assign(3 * size_t(n), 0.0);
  row_of = iperm;
  node_of.resize(size_t(n));
  for (int i = 0; i < n; ++i) node_of[size_t(i)] = perm.empty() ? i : perm[size_t(i)];
  row_mask.assign(3 * size_t(n), 0);
  held_rows.assign(size_t(n), 0);
  partial_count = 0;
  full_count = 0;
  zeroed.clear();
  zeroed.reserve(col6.size());  // each entry listed at most once
  gathered_mask.resize(0, 3);
}

void AxisMatrices::classify(const FlagMat& mask) {
  // Node by node (sequential reads of the mask's three columns); through local pointers: the
  // byte stores of the mask would otherwise make the compiler reload every member's data
  // pointer.
  const int* ro = row_of.data();
  std::uint8_t* rm = row_mask.data();
  int* hr = held_rows.data();
  const std::uint8_t* md0 = mask.col(0).data();
  const std::uint8_t* md1 = mask.col(1).data();
  const std::uint8_t* md2 = mask.col(2).data();
  const int rows = n;
  int held = 0, partial = 0;  // rows constrained on all axes (from the end), on some
  // Every row free, then the constrained ones set: the source's nodes 16 at a time, a run of
  // 16 free on every axis (most) passed over without a look at each node.
  {
    const size_t bytes = 3 * size_t(rows);
    size_t b = 0;
    for (; b + 16 <= bytes; b += 16) _mm_storeu_si128(reinterpret_cast<__m128i*>(rm + b), _mm_setzero_si128());
    for (; b < bytes; ++b) rm[b] = 0;
  }
  auto one = [&](int v) {
    const std::uint8_t h0 = md0[v] != 0, h1 = md1[v] != 0, h2 = md2[v] != 0;
    if ((h0 | h1 | h2) == 0) return;  // most rows: free on every axis
    const size_t i = size_t(ro[v]);
    std::uint8_t* mi = rm + 3 * i;
    mi[0] = h0;
    mi[1] = h1;
    mi[2] = h2;
    if (h0 & h1 & h2) hr[size_t(rows - 1 - held++)] = int(i);
    else hr[size_t(partial++)] = int(i);
  };
  int v = 0;
  for (; v + 16 <= rows; v += 16) {
    if (simd::none_set16(md0 + v) && simd::none_set16(md1 + v) && simd::none_set16(md2 + v)) continue;
    for (int k = v; k < v + 16; ++k) one(k);
  }
  for (; v < rows; ++v) one(v);
  partial_count = partial;
  full_count = held;
  // The entries in the rows and columns of the nodes constrained on every axis (most of the
  // constrained ones: held and prescribed nodes), each once (within the capacity reserved by
  // analyze()); those of a node constrained on some axes only are left to the kernels
  // (multiply_block, the factorisation).
  const int* cp6 = col6.data();
  const int* st = start.data();
  zeroed.clear();
  for (int k = rows - held; k < rows; ++k) {
    const int i = hr[k];
    for (int q = st[i]; q < st[i + 1]; ++q) {
      const int j = cp6[q] / 6;
      zeroed.push_back(q);
      if (rm[3 * j] & rm[3 * j + 1] & rm[3 * j + 2]) continue;  // row j is listed in its own turn
      for (int t = st[j]; t < st[j + 1]; ++t)
        if (cp6[t] == 6 * i) {
          zeroed.push_back(t);
          break;
        }
    }
  }
  gathered_mask = mask;
}

void AxisMatrices::gather(const AxisStiffness& K, const FlagMat& mask, const NodeMat* springs) {
  if (gathered_mask.rows() != mask.rows() ||
      std::memcmp(gathered_mask.data(), mask.data(), size_t(mask.size())) != 0)
    classify(mask);
  // The free diagonal values row by row (each row of diag written whole, in order; the
  // columns of K read at the row's node), with the springs when there are (a `+ 0.0`
  // otherwise, so a -0 would still read +0); then 1 on the constrained entries.
  const int* node = node_of.data();
  double* dg = diag.data();
  const double* kd0 = K.diagonal.col(0).data();
  const double* kd1 = K.diagonal.col(1).data();
  const double* kd2 = K.diagonal.col(2).data();
  const int rows = n;
  if (springs) {
    const double* sd0 = springs->col(0).data();
    const double* sd1 = springs->col(1).data();
    const double* sd2 = springs->col(2).data();
    for (int i = 0; i < rows; ++i) {
      const size_t v = size_t(node[i]);
      dg[3 * size_t(i)] = kd0[v] + sd0[v];
      dg[3 * size_t(i) + 1] = kd1[v] + sd1[v];
      dg[3 * size_t(i) + 2] = kd2[v] + sd2[v];
    }
  } else {
    for (int i = 0; i < rows; ++i) {
      const size_t v = size_t(node[i]);
      dg[3 * size_t(i)] = kd0[v] + 0.0;
      dg[3 * size_t(i) + 1] = kd1[v] + 0.0;
      dg[3 * size_t(i) + 2] = kd2[v] + 0.0;
    }
  }
  const std::uint8_t* rm = row_mask.data();
  const int* hr = held_rows.data();
  for (int k = 0; k < partial_count; ++k) {
    const size_t i = size_t(hr[k]);
    for (size_t d = 0; d < 3; ++d)
      if (rm[3 * i + d]) dg[3 * i + d] = 1.0;
  }
  for (int k = rows - full_count; k < rows; ++k) {
    double* di = dg + 3 * size_t(hr[k]);
    di[0] = di[1] = di[2] = 1.0;
  }
  // One value per entry for the three axes (two at a time), then the listed entries zeroed.
  const double* weight = K.weight.data();
  const int* edge = off_edge.data();
  double* o = off.data();
  const size_t m = off.size();
  size_t p = 0;
  for (; p + 2 <= m; p += 2) simd::store2(o + p, -simd::V2{weight[edge[p]], weight[edge[p + 1]]});
  if (p < m) o[p] = -weight[edge[p]];
  for (const int q : zeroed) o[q] = 0.0;
}

namespace {

// After the product with the stored values: the rows and columns of the entries constrained
// on some axes only (rare) made the identity's on those axes, for one vector of axis d whose
// row i is at x[i * S] (S = W: column c of a block, from x + c; S = 1: a vector alone). Row i
// of K^d keeps its diagonal term alone; column i's terms leave the free rows' sums; dot
// follows.
template <int S>
void eliminate_constrained_vector(const AxisMatrices& K, int d, const double* x, double* y, double& dot) {
  for (int k = 0; k < K.partial_count; ++k) {
    const int i = K.held_rows[size_t(k)];
    if (!K.constrained(i, d)) continue;
    const double xi = x[size_t(i) * S];
    double& yi = y[size_t(i) * S];
    const double now = K.diag[3 * size_t(i) + size_t(d)] * xi;
    dot += xi * (now - yi);
    yi = now;
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p) {
      const int j = K.column(size_t(p));
      if (K.constrained(j, d)) continue;  // its own row is the identity's (or zeroed)
      const double t = K.off[size_t(p)] * xi;
      y[size_t(j) * S] -= t;
      dot -= x[size_t(j) * S] * t;
    }
  }
}

template <int W>
void eliminate_constrained(const AxisMatrices& K, const double* x, double* y, double* dot) {
  if (K.partial_count == 0) return;
  for (int c = 0; c < W; ++c) eliminate_constrained_vector<W>(K, axis_of<W>(c), x + c, y + c, dot[c]);
}

// K's arrays as the row products read them (taken once per product, not per row: GCC
// reloads a member's data pointer after stores it cannot prove apart).
struct RowArrays {
  const int* start;
  const int* col6;
  const double* off;
  const double* diag;
  explicit RowArrays(const AxisMatrices& K) : start(K.start.data()), col6(K.col6.data()), off(K.off.data()), diag(K.diag.data()) {}
};

// Row i of K x for a block of 6 (multiply_block and residual_block share it): lanes are the
// two vectors of an axis (r^d, s^d), one value for the six.
inline void row_product6(const RowArrays& k, const double* x, int i, simd::V2& a0, simd::V2& a1, simd::V2& a2) {
  using simd::load2;
  using simd::splat;
  const double* xi = x + size_t(i) * 6;
  const double* di = k.diag + 3 * size_t(i);
  a0 = splat(di[0]) * load2(xi);
  a1 = splat(di[1]) * load2(xi + 2);
  a2 = splat(di[2]) * load2(xi + 4);
  for (int p = k.start[i]; p < k.start[i + 1]; ++p) {
    const double* xj = block_row<6>(x, k.col6[p]);
    const simd::V2 x0 = load2(xj), x1 = load2(xj + 2), x2 = load2(xj + 4), v = splat(k.off[p]);
    a0 += v * x0;
    a1 += v * x1;
    a2 += v * x2;
  }
}

// The same with AVX2 (simd4.hpp): lanes 0-3 of a01 are a0 and a1 above, a2 the same, each
// lane with the same operations in the same order (so the same bits).
VDM_AVX2 inline void row_product6_avx2(const RowArrays& k, const double* x, int i, simd::V4& a01, simd::V2& a2) {
  using simd::load2;
  using simd::load4;
  const double* xi = x + size_t(i) * 6;
  const double* di = k.diag + 3 * size_t(i);
  a01 = simd::dup01(load2(di)) * load4(xi);
  a2 = simd::splat(di[2]) * load2(xi + 4);
  for (int p = k.start[i]; p < k.start[i + 1]; ++p) {
    const double* xj = block_row<6>(x, k.col6[p]);
    const simd::V4 v = simd::splat4(k.off[p]);
    a01 += v * load4(xj);
    a2 += simd::low2(v) * load2(xj + 4);
  }
}

// multiply_block<6> with AVX2 (K's arrays by value, as below).
VDM_AVX2 void multiply_block6_avx2(const RowArrays rows, int n, const double* x, double* y, double* dot) {
  using simd::V2;
  using simd::V4;
  using simd::load2;
  using simd::load4;
  V4 d01 = {0, 0, 0, 0};
  V2 d2 = {0, 0};
  for (int i = 0; i < n; ++i) {
    const double* xi = x + size_t(i) * 6;
    V4 a01;
    V2 a2;
    row_product6_avx2(rows, x, i, a01, a2);
    double* yi = y + size_t(i) * 6;
    simd::store4(yi, a01);
    simd::store2(yi + 4, a2);
    d01 += load4(xi) * a01;
    d2 += load2(xi + 4) * a2;
  }
  simd::store4(dot, d01);
  simd::store2(dot + 4, d2);
}

// Row i of K x for a block of 3: x and y together (their values are adjacent), z alone.
inline void row_product3(const RowArrays& k, const double* x, int i, simd::V2& axy, double& az) {
  using simd::load2;
  using simd::splat;
  const double* xi = x + size_t(i) * 3;
  const double* di = k.diag + 3 * size_t(i);
  axy = load2(di) * load2(xi);
  az = di[2] * xi[2];
  for (int p = k.start[i]; p < k.start[i + 1]; ++p) {
    const double v = k.off[p];
    const double* xj = block_row<3>(x, k.col6[p]);
    axy += splat(v) * load2(xj);
    az += v * xj[2];
  }
}

}  // namespace

template <int W>
void multiply_block(const AxisMatrices& K, const double* x, double* y, double* dot) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  // The variant chosen first (nothing live across the call: the SSE2 loop compiles as alone).
  if (W == 6 && simd::avx2_enabled()) {
    multiply_block6_avx2(RowArrays(K), K.n, x, y, dot);
    eliminate_constrained<W>(K, x, y, dot);
    return;
  }
  const RowArrays rows(K);
  using simd::V2;
  using simd::load2;
  if constexpr (W == 6) {
    // Lanes: the two vectors of an axis (r^d, s^d); one value for the six.
    V2 d0 = {0, 0}, d1 = {0, 0}, d2 = {0, 0};
    for (int i = 0; i < K.n; ++i) {
      const double* xi = x + size_t(i) * 6;
      V2 a0, a1, a2;
      row_product6(rows, x, i, a0, a1, a2);
      double* yi = y + size_t(i) * 6;
      simd::store2(yi, a0);
      simd::store2(yi + 2, a1);
      simd::store2(yi + 4, a2);
      d0 += load2(xi) * a0;
      d1 += load2(xi + 2) * a1;
      d2 += load2(xi + 4) * a2;
    }
    simd::store2(dot, d0);
    simd::store2(dot + 2, d1);
    simd::store2(dot + 4, d2);
  } else {
    // Lanes: x and y together (their values are adjacent), z alone.
    V2 dxy = {0, 0};
    double dz = 0;
    for (int i = 0; i < K.n; ++i) {
      const double* xi = x + size_t(i) * 3;
      V2 axy;
      double az;
      row_product3(rows, x, i, axy, az);
      double* yi = y + size_t(i) * 3;
      simd::store2(yi, axy);
      yi[2] = az;
      dxy += load2(xi) * axy;
      dz += xi[2] * az;
    }
    simd::store2(dot, dxy);
    dot[2] = dz;
  }
  eliminate_constrained<W>(K, x, y, dot);
}

namespace {

// Row i of b for residual_rows<6>, as the SSE2 pass takes it (c0, c1, c2: the lanes of
// multiply_block) or the AVX2 one (c01, c2): from a block of 6, or from the source's columns.
struct BlockRows6 {
  const double* b;
  void operator()(int i, simd::V2& c0, simd::V2& c1, simd::V2& c2) const {
    const double* bi = b + size_t(i) * 6;
    c0 = simd::load2(bi);
    c1 = simd::load2(bi + 2);
    c2 = simd::load2(bi + 4);
  }
  VDM_AVX2 void operator()(int i, simd::V4& c01, simd::V2& c2) const {
    const double* bi = b + size_t(i) * 6;
    c01 = simd::load4(bi);
    c2 = simd::load2(bi + 4);
  }
};

struct SourceRows6 {
  const int* node;     // K.node_of
  const double* b0;    // system 0's n x 3 column-major matrix
  const double* b1;    // system 1's
  size_t n, n2;        // the columns' offsets
  void operator()(int i, simd::V2& c0, simd::V2& c1, simd::V2& c2) const {
    const size_t v = size_t(node[i]);
    c0 = simd::V2{b0[v], b1[v]};
    c1 = simd::V2{b0[v + n], b1[v + n]};
    c2 = simd::V2{b0[v + n2], b1[v + n2]};
  }
  VDM_AVX2 void operator()(int i, simd::V4& c01, simd::V2& c2) const {
    const size_t v = size_t(node[i]);
    c01 = simd::V4{b0[v], b1[v], b0[v + n], b1[v + n]};
    c2 = simd::V2{b0[v + n2], b1[v + n2]};
  }
};

// residual_rows<6> with AVX2: the lanes of multiply_block6_avx2, each with the SSE2 pass's
// operations in its order. K's arrays and b_row by value: local copies, kept in registers
// across the stores (through references they were reloaded on every row).
template <class BRow>
VDM_AVX2 void residual_rows6_avx2(const RowArrays rows, int n, const BRow b_row, const double* x, double* r,
                                  double* bn, double* rn) {
  using simd::V2;
  using simd::V4;
  V4 b01 = {0, 0, 0, 0}, r01 = {0, 0, 0, 0};
  V2 b2 = {0, 0}, r2 = {0, 0};
  for (int i = 0; i < n; ++i) {
    V4 a01;
    V2 a2;
    row_product6_avx2(rows, x, i, a01, a2);
    V4 c01;
    V2 c2;
    b_row(i, c01, c2);
    b01 += c01 * c01;
    b2 += c2 * c2;
    const V4 e01 = c01 - a01;
    const V2 e2 = c2 - a2;
    double* ri = r + size_t(i) * 6;
    simd::store4(ri, e01);
    simd::store2(ri + 4, e2);
    r01 += e01 * e01;
    r2 += e2 * e2;
  }
  simd::store4(bn, b01);
  simd::store2(bn + 4, b2);
  simd::store4(rn, r01);
  simd::store2(rn + 4, r2);
}

// residual_block's pass, row i of b from b_row: b_row(i, c0, c1, c2) for W = 6 (BlockRows6,
// SourceRows6), b_row(i, cxy, cz) for W = 3.
template <int W, class BRow>
void residual_rows(const AxisMatrices& K, const BRow& b_row, const double* x, double* r, double* bn, double* rn) {
  const RowArrays rows(K);
  using simd::V2;
  using simd::store2;
  if constexpr (W == 6) {
    // multiply_block's row, then the row's residual (lanes as there).
    V2 b0 = {0, 0}, b1 = {0, 0}, b2 = {0, 0}, r0 = {0, 0}, r1 = {0, 0}, r2 = {0, 0};
    for (int i = 0; i < K.n; ++i) {
      V2 a0, a1, a2;
      row_product6(rows, x, i, a0, a1, a2);
      V2 c0, c1, c2;
      b_row(i, c0, c1, c2);
      b0 += c0 * c0;
      b1 += c1 * c1;
      b2 += c2 * c2;
      const V2 e0 = c0 - a0, e1 = c1 - a1, e2 = c2 - a2;
      double* ri = r + size_t(i) * 6;
      store2(ri, e0);
      store2(ri + 2, e1);
      store2(ri + 4, e2);
      r0 += e0 * e0;
      r1 += e1 * e1;
      r2 += e2 * e2;
    }
    store2(bn, b0);
    store2(bn + 2, b1);
    store2(bn + 4, b2);
    store2(rn, r0);
    store2(rn + 2, r1);
    store2(rn + 4, r2);
  } else {
    V2 bxy = {0, 0}, rxy = {0, 0};
    double bz = 0, rz = 0;
    for (int i = 0; i < K.n; ++i) {
      V2 axy;
      double az;
      row_product3(rows, x, i, axy, az);
      V2 cxy;
      double cz;
      b_row(i, cxy, cz);
      bxy += cxy * cxy;
      bz += cz * cz;
      const V2 exy = cxy - axy;
      const double ez = cz - az;
      double* ri = r + size_t(i) * 3;
      store2(ri, exy);
      ri[2] = ez;
      rxy += exy * exy;
      rz += ez * ez;
    }
    store2(bn, bxy);
    bn[2] = bz;
    store2(rn, rxy);
    rn[2] = rz;
  }
}

}  // namespace

template <int W>
bool residual_block(const AxisMatrices& K, const double* b, const double* x, double* r, double* bn, double* rn) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  if (K.partial_count != 0) return false;
  using simd::V2;
  using simd::load2;
  if constexpr (W == 6) {
    if (simd::avx2_enabled()) residual_rows6_avx2(RowArrays(K), K.n, BlockRows6{b}, x, r, bn, rn);
    else residual_rows<W>(K, BlockRows6{b}, x, r, bn, rn);
  } else {
    auto b_row = [b](int i, V2& cxy, double& cz) {
      const double* bi = b + size_t(i) * 3;
      cxy = load2(bi);
      cz = bi[2];
    };
    residual_rows<W>(K, b_row, x, r, bn, rn);
  }
  return true;
}

template <int W>
bool residual_block(const AxisMatrices& K, const std::array<const double*, W / 3>& b_src, const double* x, double* r,
                    double* bn, double* rn) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  if (K.partial_count != 0) return false;
  // The variant chosen first, as in multiply_block.
  const bool avx2 = W == 6 && simd::avx2_enabled();
  using simd::V2;
  const int* node = K.node_of.data();
  const size_t n = size_t(K.n), n2 = 2 * n;  // the columns' offsets
  if constexpr (W == 6) {
    const SourceRows6 b_row{node, b_src[0], b_src[1], n, n2};
    if (avx2) residual_rows6_avx2(RowArrays(K), K.n, b_row, x, r, bn, rn);
    else residual_rows<W>(K, b_row, x, r, bn, rn);
  } else {
    const double* b0 = b_src[0];
    auto b_row = [node, b0, n, n2](int i, V2& cxy, double& cz) {
      const size_t v = size_t(node[i]);
      cxy = V2{b0[v], b0[v + n]};
      cz = b0[v + n2];
    };
    residual_rows<W>(K, b_row, x, r, bn, rn);
  }
  return true;
}

double multiply_axis(const AxisMatrices& K, int d, const double* x, double* y) {
  const int* start = K.start.data();
  const unsigned* col6 = reinterpret_cast<const unsigned*>(K.col6.data());  // (>= 0: unsigned / 6 is cheaper)
  const double* off = K.off.data();
  const double* diag = K.diag.data() + d;
  double dot = 0.0;
  for (int i = 0; i < K.n; ++i) {  // multiply_block's operations on one lane of axis d, in its order
    const double xi = x[i];
    double a = diag[3 * size_t(i)] * xi;
    for (int p = start[i]; p < start[i + 1]; ++p) a += off[p] * x[col6[p] / 6u];
    y[i] = a;
    dot += xi * a;
  }
  eliminate_constrained_vector<1>(K, d, x, y, dot);
  return dot;
}

template bool residual_block<3>(const AxisMatrices&, const double*, const double*, double*, double*, double*);
template bool residual_block<6>(const AxisMatrices&, const double*, const double*, double*, double*, double*);
template bool residual_block<3>(const AxisMatrices&, const std::array<const double*, 1>&, const double*, double*,
                                double*, double*);
template bool residual_block<6>(const AxisMatrices&, const std::array<const double*, 2>&, const double*, double*,
                                double*, double*);
template void multiply_block<3>(const AxisMatrices&, const double*, double*, double*);
template void multiply_block<6>(const AxisMatrices&, const double*, double*, double*);

}  // namespace vdm
