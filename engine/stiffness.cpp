#include "engine/stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/simd2.hpp"

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

namespace {

// w_ij by eq (4) as written (a division), for an edge with a floored end.
inline double plain_weight(double bc, double norm_i, double norm_j, double vol_i, double vol_j) {
  const double a = 0.5 * (norm_i + norm_j);
  return bc * a * a / (0.5 * (vol_i + vol_j));
}

}  // namespace

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& area_norms, const Vec& Vi,
                        const VolumeScale& how, const Vec& extra_diagonal, AxisStiffness& K, Vec& scratch) {
  // Connectivity: a graph Laplacian with weights w_ij, the same on every axis; its diagonal
  // sums in `scratch`.
  double* lap = scratch.data();
  std::fill(lap, lap + m.n, 0.0);
  const double bc = m.connectivity_modulus;
  const double* norm = area_norms.data();
  const double* vol = Vi.data();
  double* weight = K.weight.data();
  const std::array<int, 2>* edges = m.edges.data();
  const size_t edge_count = m.edges.size();
  const double per_area = 0.5 * bc / how.scale;  // w_ij / (|A_i| + |A_j|) where no end is floored
  if (m.membrane_capsule()) {
    // The membrane's weights are fixed at the rest surface (docs/model.md).
    std::copy(m.capsule_weight.data(), m.capsule_weight.data() + edge_count, weight);
    std::copy(m.capsule_diagonal.data(), m.capsule_diagonal.data() + m.n, lap);
  } else if (!how.any_floored) {
    for (size_t e = 0; e < edge_count; ++e) {
      const int i = edges[e][0], j = edges[e][1];
      const double w = per_area * (norm[i] + norm[j]);
      weight[e] = w;
      lap[i] += w;
      lap[j] += w;
    }
  } else {
    for (size_t e = 0; e < edge_count; ++e) {
      const int i = edges[e][0], j = edges[e][1];
      const double w = how.floored(norm[i]) || how.floored(norm[j]) ? plain_weight(bc, norm[i], norm[j], vol[i], vol[j])
                                                                     : per_area * (norm[i] + norm[j]);
      weight[e] = w;
      lap[i] += w;
      lap[j] += w;
    }
  }
  // Diagonal: the Laplacian's, then the bulk term per node and axis (one division by V_i
  // per node for the three axes), two nodes at a time.
  using simd::V2;
  using simd::load2;
  const bool extra = extra_diagonal.size() == m.n;
  const double* ex = extra ? extra_diagonal.data() : nullptr;
  const double floor = m.axis_stiffness_floor;
  double* diag[3] = {K.diagonal.col(0).data(), K.diagonal.col(1).data(), K.diagonal.col(2).data()};
  const double* a[3] = {A.col(0).data(), A.col(1).data(), A.col(2).data()};
  const double* bulk[3] = {m.bulk.col(0).data(), m.bulk.col(1).data(), m.bulk.col(2).data()};
  int i = 0;
  for (; i + 2 <= m.n; i += 2) {
    const V2 inv_v = simd::splat(1.0) / load2(vol + i);
    const V2 nn = load2(norm + i);
    const V2 a2 = simd::splat(floor) * (nn * nn);
    const V2 l = load2(lap + i);
    for (int d = 0; d < 3; ++d) {
      const V2 ad = load2(a[d] + i);
      V2 k = l + load2(bulk[d] + i) * simd::max2(ad * ad, a2) * inv_v;
      if (extra) k += load2(ex + i);
      simd::store2(diag[d] + i, k);
    }
  }
  for (; i < m.n; ++i) {
    const double inv_v = 1.0 / vol[i];
    const double a2 = floor * (norm[i] * norm[i]);
    for (int d = 0; d < 3; ++d) {
      diag[d][i] = lap[i] + bulk[d][i] * std::max(a[d][i] * a[d][i], a2) * inv_v;
      if (extra) diag[d][i] += ex[i];
    }
  }
}

void assemble_stiffness(const TissueModel& m, const NodeMat& A, const Vec& Vi, const Vec& extra_diagonal,
                        std::array<SpMat, 3>& K) {
  Vec norms(m.n), scratch(m.n);
  for (int i = 0; i < m.n; ++i) norms[i] = A.row(i).norm();
  AxisStiffness k{Vec(Eigen::Index(m.edges.size())), NodeMat(m.n, 3)};
  assemble_stiffness(m, A, norms, Vi, VolumeScale(), extra_diagonal, k, scratch);
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

void eliminate_rhs(const NeighbourLists& neighbours, const AxisStiffness& K, const FlagMat& mask, const NodeMat* f,
                   const NodeMat& u_fixed, NodeMat& rhs) {
  // The N x 3 arrays as runs of 3 N entries (entry d N + i: node i, axis d).
  const size_t n = size_t(K.diagonal.rows()), count = 3 * n;
  const std::uint8_t* mk = mask.data();
  const double* uf = u_fixed.data();
  double* r = rhs.data();
  // The loads, or zero, on the free entries and the values on the constrained ones; blocks of
  // 16 entries without a constrained one (most) copied whole.
  const double* fd = f ? f->data() : nullptr;
  auto one_by_one = [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) r[k] = mk[k] ? uf[k] : fd ? fd[k] : 0.0;
  };
  size_t k = 0;
  for (; k + 16 <= count; k += 16) {
    if (!simd::none_set16(mk + k)) one_by_one(k, k + 16);
    else if (fd) std::copy(fd + k, fd + k + 16, r + k);
    else std::fill(r + k, r + k + 16, 0.0);
  }
  one_by_one(k, count);
  // Each constrained entry's value moves to its free neighbours on its axis (K_ij = -w_ij),
  // through its node's neighbour list (the pattern's column without the diagonal, in its
  // order). The constrained entries are found 16 flags at a time again; one whose value is
  // zero (a held entry) moves nothing.
  const int* begin = neighbours.begin.data();
  const NeighbourLists::Entry* entries = neighbours.entries.data();
  const double* w = K.weight.data();
  auto move_value = [&](size_t k) {
    if (!mk[k] || uf[k] == 0.0) return;
    const size_t axis = k / n * n;  // entry of node 0 on k's axis
    const int j = int(k - axis);
    for (int s = begin[j]; s < begin[j + 1]; ++s) {
      const size_t i = axis + size_t(entries[s].node);
      if (!mk[i]) r[i] += w[entries[s].edge] * uf[k];
    }
  };
  for (k = 0; k + 16 <= count; k += 16)
    if (!simd::none_set16(mk + k))
      for (size_t e = k; e < k + 16; ++e) move_value(e);
  for (; k < count; ++k) move_value(k);
}

void eliminate_rhs(const NeighbourLists& neighbours, const AxisStiffness& K, const FlagMat& mask,
                   const std::vector<int>& held_entries, const std::vector<int>& prescribed_entries, const NodeMat* f,
                   const NodeMat& u_fixed, NodeMat& rhs, bool zero_elsewhere) {
  const size_t n = size_t(K.diagonal.rows()), count = 3 * n;
  const std::uint8_t* mk = mask.data();
  const double* uf = u_fixed.data();
  double* r = rhs.data();
  if (f) {
    // The loads everywhere (16 entries at a time: inline stores, where one call of std::copy
    // over the whole array goes to the library's string instructions); then the values on
    // the constrained entries.
    const double* fd = f->data();
    size_t k = 0;
    for (; k + 16 <= count; k += 16) std::copy(fd + k, fd + k + 16, r + k);
    for (; k < count; ++k) r[k] = fd[k];
    for (const int e : held_entries) r[e] = uf[e];
  } else if (zero_elsewhere) {
    clear_prescribed_support(neighbours, prescribed_entries, rhs);
  } else {
    // Zeros everywhere (the held entries' values among them), as vector stores: GCC turns a
    // fill of a constant 16 entries into a `rep stos` per block, slow to start.
    const simd::V2 zero = {0.0, 0.0};
    size_t k = 0;
    for (; k + 2 <= count; k += 2) simd::store2(r + k, zero);
    for (; k < count; ++k) r[k] = 0.0;
  }
  for (const int e : prescribed_entries) r[e] = uf[e];
  // Each prescribed entry's value (the held ones' are zero: they move nothing) to its free
  // neighbours on its axis, the entries in ascending order as the mask's scan takes them.
  const int* begin = neighbours.begin.data();
  const NeighbourLists::Entry* list = neighbours.entries.data();
  const double* w = K.weight.data();
  for (const int e : prescribed_entries) {
    const size_t k = size_t(e);
    if (uf[k] == 0.0) continue;
    const size_t axis = k / n * n;  // entry of node 0 on k's axis
    const int j = int(k - axis);
    for (int s = begin[j]; s < begin[j + 1]; ++s) {
      const size_t i = axis + size_t(list[s].node);
      if (!mk[i]) r[i] += w[list[s].edge] * uf[k];
    }
  }
}

void clear_prescribed_support(const NeighbourLists& neighbours, const std::vector<int>& prescribed_entries,
                              NodeMat& rhs) {
  const size_t n = size_t(rhs.rows());
  double* r = rhs.data();
  const int* begin = neighbours.begin.data();
  const NeighbourLists::Entry* list = neighbours.entries.data();
  for (const int e : prescribed_entries) {
    const size_t k = size_t(e);
    r[k] = 0.0;
    const size_t axis = k / n * n;
    const int j = int(k - axis);
    for (int s = begin[j]; s < begin[j + 1]; ++s) r[axis + size_t(list[s].node)] = 0.0;
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
