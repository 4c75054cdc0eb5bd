#include "engine/axis_matrices.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "engine/simd2.hpp"

namespace vdm {

void AxisMatrices::analyze(const SpMat& pattern, const std::vector<int>& perm) {
  n = static_cast<int>(pattern.cols());
  std::vector<int> iperm(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) iperm[size_t(perm.empty() ? i : perm[size_t(i)])] = i;
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  start.assign(size_t(n) + 1, 0);
  col.clear();
  off_src.clear();
  diag_src.assign(size_t(n), -1);
  std::vector<std::pair<int, int>> row;  // (column here, value index in the source)
  for (int i = 0; i < n; ++i) {
    const int node = perm.empty() ? i : perm[size_t(i)];
    row.clear();
    // K is symmetric: row `node` is column `node`.
    for (int k = outer[node]; k < outer[node + 1]; ++k) {
      if (inner[k] == node) diag_src[size_t(i)] = k;
      else row.emplace_back(iperm[size_t(inner[k])], k);
    }
    if (diag_src[size_t(i)] < 0) throw std::invalid_argument("AxisMatrices: the pattern lacks a diagonal entry");
    std::sort(row.begin(), row.end());
    for (const auto& e : row) {
      col.push_back(e.first);
      off_src.push_back(e.second);
    }
    start[size_t(i) + 1] = static_cast<int>(col.size());
  }
  off.assign(3 * col.size(), 0.0);
  diag.assign(3 * size_t(n), 0.0);
  row_of = iperm;
  row_mask.assign(3 * size_t(n), 0);
  held_rows.assign(size_t(n), 0);
}

void AxisMatrices::gather(const std::array<SpMat, 3>& K) {
  const double* v0 = K[0].valuePtr();
  const double* v1 = K[1].valuePtr();
  const double* v2 = K[2].valuePtr();
  for (size_t e = 0; e < off_src.size(); ++e) {
    const int k = off_src[e];
    off[3 * e] = v0[k];
    off[3 * e + 1] = v1[k];
    off[3 * e + 2] = v2[k];
  }
  for (size_t i = 0; i < diag_src.size(); ++i) {
    const int k = diag_src[i];
    diag[3 * i] = v0[k];
    diag[3 * i + 1] = v1[k];
    diag[3 * i + 2] = v2[k];
  }
}

void AxisMatrices::analyze(const StiffnessPattern& pattern, const std::vector<int>& perm) {
  analyze(pattern.matrix, perm);
  std::vector<int> slot_edge(size_t(pattern.matrix.nonZeros()), -1);
  for (size_t e = 0; e < pattern.edge_slot.size(); ++e)
    slot_edge[size_t(pattern.edge_slot[e][0])] = slot_edge[size_t(pattern.edge_slot[e][1])] = int(e);
  off_edge.resize(off_src.size());
  for (size_t p = 0; p < off_src.size(); ++p) {
    off_edge[p] = slot_edge[size_t(off_src[p])];
    if (off_edge[p] < 0) throw std::invalid_argument("AxisMatrices: an off-diagonal entry without its edge");
  }
  // The SpMat sources are not used with a StiffnessPattern (its gather() reads off_edge).
  std::vector<int>().swap(off_src);
  std::vector<int>().swap(diag_src);
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
  size_t held = 0;
  for (int v = 0; v < n; ++v) {
    const size_t i = size_t(row_of[size_t(v)]);
    std::uint8_t any = 0;
    for (int d = 0; d < 3; ++d) {
      const std::uint8_t h = md[d][v] != 0;
      rm[3 * i + size_t(d)] = h;
      diag[3 * i + size_t(d)] = h ? 1.0 : kd[d][v] + (springs ? sd[d][v] : 0.0);
      any |= h;
    }
    if (any) held_rows[held++] = int(i);
  }
  // Every entry unmasked, then the rows and columns of the constrained entries (few: the
  // held and prescribed nodes) zeroed on their axes.
  const double* weight = K.weight.data();
  for (size_t p = 0; p < off_edge.size(); ++p) {
    const double v = -weight[off_edge[p]];
    off[3 * p] = off[3 * p + 1] = off[3 * p + 2] = v;
  }
  for (size_t k = 0; k < held; ++k) {
    const int i = held_rows[k];
    const std::uint8_t* mi = rm + 3 * size_t(i);
    for (int p = start[size_t(i)]; p < start[size_t(i) + 1]; ++p) {
      const int j = col[size_t(p)];
      for (int q = start[size_t(j)]; q < start[size_t(j) + 1]; ++q)
        if (col[size_t(q)] == i) {
          for (int d = 0; d < 3; ++d)
            if (mi[d]) off[3 * size_t(p) + size_t(d)] = off[3 * size_t(q) + size_t(d)] = 0.0;
          break;
        }
    }
  }
}

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
    // Lanes: the two vectors of an axis (r^d, s^d) share the value of K^d.
    V2 d0 = {0, 0}, d1 = {0, 0}, d2 = {0, 0};
    for (int i = 0; i < K.n; ++i) {
      const double* xi = x + size_t(i) * 6;
      const double* di = diag + 3 * size_t(i);
      V2 a0 = splat(di[0]) * load2(xi), a1 = splat(di[1]) * load2(xi + 2), a2 = splat(di[2]) * load2(xi + 4);
      for (int p = start[i]; p < start[i + 1]; ++p) {
        const double* v = off + 3 * size_t(p);
        const double* xj = x + size_t(col[p]) * 6;
        a0 += splat(v[0]) * load2(xj);
        a1 += splat(v[1]) * load2(xj + 2);
        a2 += splat(v[2]) * load2(xj + 4);
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
        const double* v = off + 3 * size_t(p);
        const double* xj = x + size_t(col[p]) * 3;
        axy += load2(v) * load2(xj);
        az += v[2] * xj[2];
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
}

template void multiply_block<3>(const AxisMatrices&, const double*, double*, double*);
template void multiply_block<6>(const AxisMatrices&, const double*, double*, double*);

}  // namespace vdm
