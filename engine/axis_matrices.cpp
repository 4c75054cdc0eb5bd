#include "engine/axis_matrices.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "engine/simd2.hpp"

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
  col.clear();
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
      col.push_back(e.first);
      off_edge.push_back(e.second);
    }
    start[size_t(i) + 1] = static_cast<int>(col.size());
  }
  off.assign(col.size(), 0.0);
  diag.assign(3 * size_t(n), 0.0);
  row_of = iperm;
  row_mask.assign(3 * size_t(n), 0);
  held_rows.assign(size_t(n), 0);
  partial_count = 0;
}

void AxisMatrices::gather(const AxisStiffness& K, const FlagMat& mask, const NodeMat* springs) {
  // The per-node values in node order (sequential reads of the three columns; each row here
  // written whole), then the entries row by row.
  std::uint8_t* rm = row_mask.data();
  const double* kd[3] = {K.diagonal.col(0).data(), K.diagonal.col(1).data(), K.diagonal.col(2).data()};
  const std::uint8_t* md[3] = {mask.col(0).data(), mask.col(1).data(), mask.col(2).data()};
  const double* sd[3] = {nullptr, nullptr, nullptr};
  if (springs)
    for (int d = 0; d < 3; ++d) sd[d] = springs->col(d).data();
  int held = 0, partial = 0;  // rows constrained on all axes (from the end), on some
  for (int v = 0; v < n; ++v) {
    const size_t i = size_t(row_of[size_t(v)]);
    int count = 0;
    for (int d = 0; d < 3; ++d) {
      const std::uint8_t h = md[d][v] != 0;
      rm[3 * i + size_t(d)] = h;
      diag[3 * i + size_t(d)] = h ? 1.0 : kd[d][v] + (springs ? sd[d][v] : 0.0);
      count += h;
    }
    if (count == 3) held_rows[size_t(n - 1 - held++)] = int(i);
    else if (count > 0) held_rows[size_t(partial++)] = int(i);
  }
  partial_count = partial;
  // One value per entry for the three axes; the rows and columns of the nodes constrained on
  // every axis (most of the constrained ones: held and prescribed nodes) zeroed here, those
  // of a node constrained on some axes only left to the kernels (multiply_block, the
  // factorisation).
  const double* weight = K.weight.data();
  const int* edge = off_edge.data();
  double* o = off.data();
  for (size_t p = 0; p < off.size(); ++p) o[p] = -weight[edge[p]];
  for (int k = n - held; k < n; ++k) {
    const int i = held_rows[size_t(k)];
    for (int p = start[size_t(i)]; p < start[size_t(i) + 1]; ++p) {
      const int j = col[size_t(p)];
      o[p] = 0.0;
      for (int q = start[size_t(j)]; q < start[size_t(j) + 1]; ++q)
        if (col[size_t(q)] == i) {
          o[q] = 0.0;
          break;
        }
    }
  }
}

namespace {

// After the product with the stored values: the rows and columns of the entries constrained
// on some axes only (rare) made the identity's on those axes, for column c of the block. Row i
// of K^d keeps its diagonal term alone; column i's terms leave the free rows' sums; dot
// follows.
template <int W>
void eliminate_constrained_column(const AxisMatrices& K, int c, const double* x, double* y, double& dot) {
  const int d = axis_of<W>(c);
  for (int k = 0; k < K.partial_count; ++k) {
    const int i = K.held_rows[size_t(k)];
    if (!K.constrained(i, d)) continue;
    const double xi = x[size_t(i) * W + size_t(c)];
    double& yi = y[size_t(i) * W + size_t(c)];
    const double now = K.diag[3 * size_t(i) + size_t(d)] * xi;
    dot += xi * (now - yi);
    yi = now;
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p) {
      const int j = K.col[size_t(p)];
      if (K.constrained(j, d)) continue;  // its own row is the identity's (or zeroed)
      const double t = K.off[size_t(p)] * xi;
      y[size_t(j) * W + size_t(c)] -= t;
      dot -= x[size_t(j) * W + size_t(c)] * t;
    }
  }
}

template <int W>
void eliminate_constrained(const AxisMatrices& K, const double* x, double* y, double* dot) {
  if (K.partial_count == 0) return;
  for (int c = 0; c < W; ++c) eliminate_constrained_column<W>(K, c, x, y, dot[c]);
}

}  // namespace

template <int W>
void multiply_block(const AxisMatrices& K, const double* x, double* y, double* dot) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  using simd::V2;
  using simd::load2;
  using simd::splat;
  const int* start = K.start.data();
  const int* col = K.col.data();
  const double* off = K.off.data();
  const double* diag = K.diag.data();
  if constexpr (W == 6) {
    // Lanes: the two vectors of an axis (r^d, s^d); one value for the six.
    V2 d0 = {0, 0}, d1 = {0, 0}, d2 = {0, 0};
    for (int i = 0; i < K.n; ++i) {
      const double* xi = x + size_t(i) * 6;
      const double* di = diag + 3 * size_t(i);
      V2 a0 = splat(di[0]) * load2(xi), a1 = splat(di[1]) * load2(xi + 2), a2 = splat(di[2]) * load2(xi + 4);
      for (int p = start[i]; p < start[i + 1]; ++p) {
        const V2 v = splat(off[p]);
        const double* xj = x + size_t(col[p]) * 6;
        a0 += v * load2(xj);
        a1 += v * load2(xj + 2);
        a2 += v * load2(xj + 4);
      }
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
      const double* di = diag + 3 * size_t(i);
      V2 axy = load2(di) * load2(xi);
      double az = di[2] * xi[2];
      for (int p = start[i]; p < start[i + 1]; ++p) {
        const double v = off[p];
        const double* xj = x + size_t(col[p]) * 3;
        axy += splat(v) * load2(xj);
        az += v * xj[2];
      }
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

template <int W>
double multiply_column(const AxisMatrices& K, int c, const double* x, double* y) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  const int d = axis_of<W>(c);
  const int* start = K.start.data();
  const int* col = K.col.data();
  const double* off = K.off.data();
  const double* diag = K.diag.data();
  const double* xc = x + c;
  double* yc = y + c;
  double dot = 0.0;
  for (int i = 0; i < K.n; ++i) {  // multiply_block's operations on lane c, in its order
    const double xi = xc[size_t(i) * W];
    double a = diag[3 * size_t(i) + size_t(d)] * xi;
    for (int p = start[i]; p < start[i + 1]; ++p) a += off[p] * xc[size_t(col[p]) * W];
    yc[size_t(i) * W] = a;
    dot += xi * a;
  }
  eliminate_constrained_column<W>(K, c, x, y, dot);
  return dot;
}

template void multiply_block<3>(const AxisMatrices&, const double*, double*, double*);
template double multiply_column<3>(const AxisMatrices&, int, const double*, double*);
template double multiply_column<6>(const AxisMatrices&, int, const double*, double*);
template void multiply_block<6>(const AxisMatrices&, const double*, double*, double*);

}  // namespace vdm
