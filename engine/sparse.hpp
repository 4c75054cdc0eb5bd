#pragma once
// The fixed sparsity pattern of the per-axis stiffness K^d = L_w + diag(k^d): one entry per
// node and two per surface edge. Values are written in place each refresh (no rebuild).
#include <array>
#include <vector>

#include <Eigen/SparseCore>

namespace vdm {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct StiffnessPattern {
  SpMat matrix;                               // N x N, symmetric pattern, zero values
  std::vector<int> diagonal;                  // value index of (i, i)
  std::vector<std::array<int, 2>> edge_slot;  // value indices of (i, j) and (j, i) per edge
};

StiffnessPattern build_stiffness_pattern(int n, const std::vector<std::array<int, 2>>& edges);

}  // namespace vdm
