#pragma once
// The fixed sparsity pattern of the per-axis stiffness K^d = L_w + diag(k^d): one entry per
// node and two per surface edge. Values are written in place each refresh (no rebuild).
#include <array>
#include <vector>

#include <Eigen/SparseCore>

#include "engine/types.hpp"

namespace vdm {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct StiffnessPattern {
  SpMat matrix;                               // N x N, symmetric pattern, zero values
  std::vector<int> diagonal;                  // value index of (i, i)
  std::vector<std::array<int, 2>> edges;      // the node pairs (i, j) of the off-diagonal entries
  std::vector<std::array<int, 2>> edge_slot;  // value indices of (i, j) and (j, i) per edge
};

// K^d = L_w + diag(k^d) as the step keeps it: the graph Laplacian's weights, one per edge
// (the same on every axis, in StiffnessPattern::edges order), and the whole diagonal of each
// axis (the Laplacian's plus the bulk term, plus inertia). Entry (i, j) of an edge is -w_ij.
struct AxisStiffness {
  Vec weight;        // E
  NodeMat diagonal;  // N x 3
};

StiffnessPattern build_stiffness_pattern(int n, const std::vector<std::array<int, 2>>& edges);

}  // namespace vdm
