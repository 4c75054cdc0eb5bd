#include "engine/axis_matrices.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

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
}

void AxisMatrices::gather(const std::array<SpMat, 3>& K) {
  for (int d = 0; d < 3; ++d) {
    const double* v = K[size_t(d)].valuePtr();
    for (size_t e = 0; e < off_src.size(); ++e) off[3 * e + size_t(d)] = v[off_src[e]];
    for (size_t i = 0; i < diag_src.size(); ++i) diag[3 * i + size_t(d)] = v[diag_src[i]];
  }
}

template <int W>
void multiply_block(const AxisMatrices& K, const double* x, double* y, double* dot) {
  static_assert(W % 3 == 0, "blocks of whole axis triples");
  double dsum[W] = {};
  const int* start = K.start.data();
  const int* col = K.col.data();
  const double* off = K.off.data();
  const double* diag = K.diag.data();
  for (int i = 0; i < K.n; ++i) {
    const double* xi = x + size_t(i) * W;
    double acc[W];
    for (int c = 0; c < W; ++c) acc[c] = diag[3 * i + c % 3] * xi[c];
    for (int p = start[i]; p < start[i + 1]; ++p) {
      const double* v = off + 3 * size_t(p);
      const double* xj = x + size_t(col[p]) * W;
      for (int c = 0; c < W; ++c) acc[c] += v[c % 3] * xj[c];
    }
    double* yi = y + size_t(i) * W;
    for (int c = 0; c < W; ++c) {
      yi[c] = acc[c];
      dsum[c] += xi[c] * acc[c];
    }
  }
  for (int c = 0; c < W; ++c) dot[c] = dsum[c];
}

template void multiply_block<3>(const AxisMatrices&, const double*, double*, double*);
template void multiply_block<6>(const AxisMatrices&, const double*, double*, double*);

}  // namespace vdm
