#include "engine/stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vdm {

StiffnessPattern build_stiffness_pattern(int n, const std::vector<std::array<int, 2>>& edges) {
  StiffnessPattern p;
  std::vector<Eigen::Triplet<double, int>> trip;
  trip.reserve(static_cast<size_t>(n) + 2 * edges.size());
  for (int i = 0; i < n; ++i) trip.emplace_back(i, i, 0.0);
  for (const auto& e : edges) {
    trip.emplace_back(e[0], e[1], 0.0);
    trip.emplace_back(e[1], e[0], 0.0);
  }
  p.matrix.resize(n, n);
  p.matrix.setFromTriplets(trip.begin(), trip.end());
  p.matrix.makeCompressed();
  // Locate value slots: entry (row, col) lives in column col.
  auto slot = [&](int row, int col) {
    const int* outer = p.matrix.outerIndexPtr();
    const int* inner = p.matrix.innerIndexPtr();
    for (int k = outer[col]; k < outer[col + 1]; ++k)
      if (inner[k] == row) return k;
    return -1;
  };
  p.diagonal.resize(n);
  for (int i = 0; i < n; ++i) p.diagonal[i] = slot(i, i);
  p.edge_slot.resize(edges.size());
  for (size_t e = 0; e < edges.size(); ++e)
    p.edge_slot[e] = {slot(edges[e][0], edges[e][1]), slot(edges[e][1], edges[e][0])};
  return p;
}

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& Vi, const Vec& extra_diagonal,
                        std::array<SpMat, 3>& K) {
  Vec norms(m.n), scratch(m.n);
  for (int i = 0; i < m.n; ++i) norms[i] = A.row(i).norm();
  assemble_stiffness(m, A, norms, Vi, extra_diagonal, K, scratch);
}

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& area_norms, const Vec& Vi,
                        const Vec& extra_diagonal, std::array<SpMat, 3>& K, Vec& scratch) {
  double* v[3] = {K[0].valuePtr(), K[1].valuePtr(), K[2].valuePtr()};
  // Connectivity: a graph Laplacian with weights w_ij, the same on every axis. Every
  // off-diagonal entry belongs to one edge: written once; the diagonal sums in `scratch`.
  double* lap = scratch.data();
  std::fill(lap, lap + m.n, 0.0);
  const double bc = m.connectivity_modulus;
  const double* norm = area_norms.data();
  const double* vol = Vi.data();
  const std::array<int, 2>* slot = m.pattern.edge_slot.data();
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const int i = m.edges[e][0], j = m.edges[e][1];
    const double a = 0.5 * (norm[i] + norm[j]);
    const double vij = 0.5 * (vol[i] + vol[j]);
    const double w = bc * a * a / vij;
    for (int d = 0; d < 3; ++d) {
      v[d][slot[e][0]] = -w;
      v[d][slot[e][1]] = -w;
    }
    lap[i] += w;
    lap[j] += w;
  }
  // Diagonal: the Laplacian's, then the bulk term per node and axis.
  const bool extra = extra_diagonal.size() == m.n;
  const double floor = m.axis_stiffness_floor;
  for (int i = 0; i < m.n; ++i) {
    const int di = m.pattern.diagonal[size_t(i)];
    const double a2 = floor * A.row(i).squaredNorm();
    for (int d = 0; d < 3; ++d) {
      double k = lap[i] + m.bulk(i, d) * std::max(A(i, d) * A(i, d), a2) / vol[i];
      if (extra) k += extra_diagonal[i];
      v[d][di] = k;
    }
  }
}

void mask_constrained(const SpMat& K, const std::uint8_t* mask, SpMat& Km, const double* spring) {
  const int n = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* src = K.valuePtr();
  double* dst = Km.valuePtr();
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int i = inner[k];
      if (mask[i] || mask[j]) dst[k] = (i == j) ? 1.0 : 0.0;
      else dst[k] = (i == j && spring) ? src[k] + spring[i] : src[k];
    }
}

void eliminate_rhs(const SpMat& K, const std::uint8_t* mask, const double* f, const double* u_fixed,
                   double* rhs) {
  const int n = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* val = K.valuePtr();
  for (int i = 0; i < n; ++i) rhs[i] = mask[i] ? u_fixed[i] : f[i];
  for (int j = 0; j < n; ++j) {
    if (!mask[j] || u_fixed[j] == 0.0) continue;
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int i = inner[k];
      if (!mask[i]) rhs[i] -= val[k] * u_fixed[j];
    }
  }
}

void symmetric_multiply(const SpMat& K, const double* x, double* y) {
  // K is symmetric, so row i of K is column i: a gather, one pass, no scatter.
  const int n = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* val = K.valuePtr();
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) s += val[k] * x[inner[k]];
    y[i] = s;
  }
}

}  // namespace vdm

namespace vdm {

void symmetric_multiply_rows(const SpMat& K, const std::uint8_t* rows, const double* x, double* y) {
  const int n = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* val = K.valuePtr();
  for (int i = 0; i < n; ++i) {
    if (!rows[i]) continue;
    double s = 0.0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) s += val[k] * x[inner[k]];
    y[i] = s;
  }
}

}  // namespace vdm
