#include "engine/stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vdm {

StiffnessPattern build_stiffness_pattern(int n, const std::vector<std::array<int, 2>>& edges) {
  StiffnessPattern p;
  p.edges = edges;
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

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& area_norms, const Vec& Vi,
                        const Vec& extra_diagonal, AxisStiffness& K, Vec& scratch) {
  // Connectivity: a graph Laplacian with weights w_ij, the same on every axis; its diagonal
  // sums in `scratch`.
  double* lap = scratch.data();
  std::fill(lap, lap + m.n, 0.0);
  const double bc = m.connectivity_modulus;
  const double* norm = area_norms.data();
  const double* vol = Vi.data();
  double* weight = K.weight.data();
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const int i = m.edges[e][0], j = m.edges[e][1];
    const double a = 0.5 * (norm[i] + norm[j]);
    const double vij = 0.5 * (vol[i] + vol[j]);
    const double w = bc * a * a / vij;
    weight[e] = w;
    lap[i] += w;
    lap[j] += w;
  }
  // Diagonal: the Laplacian's, then the bulk term per node and axis (one division by V_i
  // per node for the three axes).
  const bool extra = extra_diagonal.size() == m.n;
  const double floor = m.axis_stiffness_floor;
  double* diag[3] = {K.diagonal.col(0).data(), K.diagonal.col(1).data(), K.diagonal.col(2).data()};
  const double* a[3] = {A.col(0).data(), A.col(1).data(), A.col(2).data()};
  const double* bulk[3] = {m.bulk.col(0).data(), m.bulk.col(1).data(), m.bulk.col(2).data()};
  for (int i = 0; i < m.n; ++i) {
    const double inv_v = 1.0 / vol[i];
    const double a2 = floor * (norm[i] * norm[i]);
    for (int d = 0; d < 3; ++d) {
      diag[d][i] = lap[i] + bulk[d][i] * std::max(a[d][i] * a[d][i], a2) * inv_v;
      if (extra) diag[d][i] += extra_diagonal[i];
    }
  }
}

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& Vi, const Vec& extra_diagonal,
                        std::array<SpMat, 3>& K) {
  Vec norms(m.n), scratch(m.n);
  for (int i = 0; i < m.n; ++i) norms[i] = A.row(i).norm();
  AxisStiffness k{Vec(Eigen::Index(m.edges.size())), NodeMat(m.n, 3)};
  assemble_stiffness(m, A, norms, Vi, extra_diagonal, k, scratch);
  to_sparse(m.pattern, k, K);
}

void to_sparse(const StiffnessPattern& p, const AxisStiffness& K, std::array<SpMat, 3>& out) {
  for (int d = 0; d < 3; ++d) {
    double* v = out[size_t(d)].valuePtr();
    for (size_t e = 0; e < p.edge_slot.size(); ++e) v[p.edge_slot[e][0]] = v[p.edge_slot[e][1]] = -K.weight[Eigen::Index(e)];
    for (size_t i = 0; i < p.diagonal.size(); ++i) v[p.diagonal[i]] = K.diagonal(Eigen::Index(i), d);
  }
}

void multiply(const StiffnessPattern& p, const AxisStiffness& K, const NodeMat& X, NodeMat& Y) {
  const Eigen::Index n = K.diagonal.rows();
  const double* x[3] = {X.col(0).data(), X.col(1).data(), X.col(2).data()};
  double* y[3] = {Y.col(0).data(), Y.col(1).data(), Y.col(2).data()};
  for (int d = 0; d < 3; ++d) {
    const double* diag = K.diagonal.col(d).data();
    for (Eigen::Index i = 0; i < n; ++i) y[d][i] = diag[i] * x[d][i];
  }
  const double* w = K.weight.data();
  for (size_t e = 0; e < p.edges.size(); ++e) {
    const int i = p.edges[e][0], j = p.edges[e][1];
    for (int d = 0; d < 3; ++d) {
      y[d][i] -= w[e] * x[d][j];
      y[d][j] -= w[e] * x[d][i];
    }
  }
}

void eliminate_rhs(const StiffnessPattern& p, const AxisStiffness& K, const FlagMat& mask, const NodeMat* f,
                   const NodeMat& u_fixed, NodeMat& rhs, std::vector<std::uint8_t>& axes) {
  const Eigen::Index n = K.diagonal.rows();
  const std::uint8_t* mk[3] = {mask.col(0).data(), mask.col(1).data(), mask.col(2).data()};
  const double* uf[3] = {u_fixed.col(0).data(), u_fixed.col(1).data(), u_fixed.col(2).data()};
  double* r[3] = {rhs.col(0).data(), rhs.col(1).data(), rhs.col(2).data()};
  axes.resize(size_t(n));
  std::uint8_t* bits = axes.data();  // bit d: entry d constrained
  for (Eigen::Index i = 0; i < n; ++i) bits[i] = std::uint8_t((mk[0][i] != 0) | (mk[1][i] != 0) << 1 | (mk[2][i] != 0) << 2);
  for (int d = 0; d < 3; ++d) {
    if (f) {
      const double* fd = f->col(d).data();
      for (Eigen::Index i = 0; i < n; ++i) r[d][i] = mk[d][i] ? uf[d][i] : fd[i];
    } else {
      for (Eigen::Index i = 0; i < n; ++i) r[d][i] = mk[d][i] ? uf[d][i] : 0.0;
    }
  }
  // Only the edges between a free and a constrained entry move values (few: around the held
  // and prescribed nodes), found by one comparison of the two nodes' bits.
  const double* w = K.weight.data();
  for (size_t e = 0; e < p.edges.size(); ++e) {
    const int i = p.edges[e][0], j = p.edges[e][1];
    const std::uint8_t differ = bits[i] ^ bits[j];
    if (!differ) continue;  // on every axis both free, or both constrained
    for (int d = 0; d < 3; ++d) {
      if (!(differ >> d & 1)) continue;
      if (bits[j] >> d & 1) r[d][i] += w[e] * uf[d][j];  // K_ij = -w
      else r[d][j] += w[e] * uf[d][i];
    }
  }
}

void mask_constrained(const SpMat& K, const std::uint8_t* mask, SpMat& Km) {
  const int n = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* src = K.valuePtr();
  double* dst = Km.valuePtr();
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      const int i = inner[k];
      if (mask[i] || mask[j]) dst[k] = (i == j) ? 1.0 : 0.0;
      else dst[k] = src[k];
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
