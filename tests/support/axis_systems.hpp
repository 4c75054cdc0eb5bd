#pragma once
// Test systems for the three-axis kernels: the per-axis stiffness of a deformed icosphere
// (Laplacian plus a different diagonal per axis), with some entries constrained on one axis
// (identity rows and columns), and a node ordering that scrambles the numbering.
#include <array>
#include <cmath>
#include <vector>

#include "engine/axis_matrices.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/stiffness.hpp"
#include "support/scenarios.hpp"

namespace vdm::axis_test {

// The model's K^x, K^y, K^z at rest as the step keeps them: edge weights and diagonals.
inline AxisStiffness edge_stiffness(const TissueModel& m) {
  NodeMat a(m.n, 3);
  Vec v(m.n), norms(m.n), scratch(m.n);
  distributed_area_vectors(m.rest.positions, m.rest.triangles, a);
  const VolumeScale how = distributed_volumes(a, enclosed_volume(m.rest.positions, m.rest.triangles, m.origin), v);
  for (int i = 0; i < m.n; ++i) norms[i] = a.row(i).norm();
  AxisStiffness k{Vec(Eigen::Index(m.edges.size())), NodeMat(m.n, 3)};
  assemble_stiffness(m, a, norms, v, how, Vec(), k, scratch);
  return k;
}

struct System {
  TissueModel model;
  std::array<SpMat, 3> K;   // masked per axis
  AxisStiffness k;          // the same unmasked, as edge weights and diagonals
  FlagMat mask;             // the constrained entries (N x 3)
  std::vector<int> perm;    // solver index -> node
};

inline System make_system(CapsuleForm capsule = CapsuleForm::membrane) {
  System s;
  TissueDef def = default_tissue(make_icosphere(0.05, 3));
  def.capsule = capsule;
  // Squash the sphere so that the three axes' diagonals differ.
  for (int i = 0; i < def.mesh.node_count(); ++i) def.mesh.positions(i, 2) *= 0.6;
  s.model = scenario::build(def);
  const TissueModel& m = s.model;
  // The same values as sparse matrices (bit for bit: the kernels' results are compared exactly).
  s.k = edge_stiffness(m);
  std::array<SpMat, 3> full = {m.pattern.matrix, m.pattern.matrix, m.pattern.matrix};
  to_sparse(m.pattern, s.k, full);
  s.mask = FlagMat::Zero(m.n, 3);
  for (int d = 0; d < 3; ++d) {
    // The bottom cap held on every axis, a band held on y only.
    for (int i = 0; i < m.n; ++i)
      s.mask(i, d) = m.rest.positions(i, 2) < -0.025 || (d == 1 && std::abs(m.rest.positions(i, 0)) < 0.005);
    s.K[size_t(d)] = m.pattern.matrix;
    mask_constrained(full[size_t(d)], s.mask.col(d).data(), s.K[size_t(d)]);
  }
  // A scrambled numbering (deterministic): i -> (i * 7919) mod n, a bijection for n not a
  // multiple of 7919.
  s.perm.resize(size_t(m.n));
  for (int i = 0; i < m.n; ++i) s.perm[size_t(i)] = int((long(i) * 7919) % m.n);
  return s;
}

// Entry (i, j) of K permuted: K(perm[i], perm[j]).
inline SpMat permuted(const SpMat& K, const std::vector<int>& perm) {
  const int n = int(K.rows());
  std::vector<int> iperm(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) iperm[size_t(perm[size_t(i)])] = i;
  std::vector<Eigen::Triplet<double, int>> t;
  for (int j = 0; j < n; ++j)
    for (SpMat::InnerIterator it(K, j); it; ++it) t.emplace_back(iperm[size_t(it.row())], iperm[size_t(j)], it.value());
  SpMat P(n, n);
  P.setFromTriplets(t.begin(), t.end());
  P.makeCompressed();
  return P;
}

// K^x, K^y, K^z of `s` (its K) as the solver stores them, in the permuted order.
inline void gather(const System& s, AxisMatrices& K) {
  K.analyze(s.model.pattern, s.perm);
  K.gather(s.k, s.mask, nullptr);
}

}  // namespace vdm::axis_test
