#include "engine/contact_compliance.hpp"

namespace vdm {

namespace {

bool is_fixed(const FlagMat& f, int i, int d) { return f.rows() > i && f(i, d) != 0; }

}  // namespace

bool PatchCompliance::compute(const NeighbourLists& nb, const AxisStiffness& K, const FlagMat& fixed_a,
                              const FlagMat& fixed_b, const std::vector<int>& nodes, int rings) {
  const int n = static_cast<int>(K.diagonal.rows());
  if (static_cast<int>(local_.size()) != n) local_.assign(static_cast<size_t>(n), -1);
  // The patch: breadth first from the contact nodes, `rings` deep.
  patch_.assign(nodes.begin(), nodes.end());
  for (size_t k = 0; k < patch_.size(); ++k) local_[static_cast<size_t>(patch_[k])] = static_cast<int>(k);
  size_t ring_begin = 0;
  for (int r = 0; r < rings; ++r) {
    const size_t ring_end = patch_.size();
    for (size_t k = ring_begin; k < ring_end; ++k) {
      const int i = patch_[k];
      for (int e = nb.begin[static_cast<size_t>(i)]; e < nb.begin[static_cast<size_t>(i) + 1]; ++e) {
        const int j = nb.entries[static_cast<size_t>(e)].node;
        if (local_[static_cast<size_t>(j)] >= 0) continue;
        local_[static_cast<size_t>(j)] = static_cast<int>(patch_.size());
        patch_.push_back(j);
      }
    }
    ring_begin = ring_end;
  }
  const int p = static_cast<int>(patch_.size()), c = static_cast<int>(nodes.size());
  bool ok = true;
  for (int d = 0; d < 3; ++d) {
    w_[d].setZero(c, c);
    unknown_.assign(static_cast<size_t>(p), -1);
    int rows = 0;
    for (int k = 0; k < p; ++k)
      if (!is_fixed(fixed_a, patch_[k], d) && !is_fixed(fixed_b, patch_[k], d)) unknown_[static_cast<size_t>(k)] = rows++;
    if (rows == 0) continue;
    triplets_.clear();
    for (int k = 0; k < p; ++k) {
      const int row = unknown_[static_cast<size_t>(k)];
      if (row < 0) continue;
      const int i = patch_[k];
      for (int e = nb.begin[static_cast<size_t>(i)]; e < nb.begin[static_cast<size_t>(i) + 1]; ++e) {
        const NeighbourLists::Entry& en = nb.entries[static_cast<size_t>(e)];
        const int lj = local_[static_cast<size_t>(en.node)];
        const int col = lj < 0 ? -1 : unknown_[static_cast<size_t>(lj)];
        if (col >= 0) triplets_.emplace_back(row, col, -K.weight[en.edge]);
      }
      triplets_.emplace_back(row, row, K.diagonal(i, d));
    }
    matrix_.resize(rows, rows);
    matrix_.setFromTriplets(triplets_.begin(), triplets_.end());
    ldlt_.compute(matrix_);
    const bool factored = ldlt_.info() == Eigen::Success && (ldlt_.vectorD().array() > 0.0).all();
    if (!factored) {
      ok = false;
      for (int a = 0; a < c; ++a) {
        const int row = unknown_[static_cast<size_t>(a)];
        if (row >= 0) w_[d](a, a) = 1.0 / std::max(K.diagonal(nodes[static_cast<size_t>(a)], d), 1e-300);
      }
      continue;
    }
    rhs_.setZero(rows, c);
    for (int a = 0; a < c; ++a) {
      const int row = unknown_[static_cast<size_t>(a)];
      if (row >= 0) rhs_(row, a) = 1.0;
    }
    solution_ = ldlt_.solve(rhs_);
    for (int a = 0; a < c; ++a) {
      const int row = unknown_[static_cast<size_t>(a)];
      if (row < 0) continue;
      for (int b = 0; b < c; ++b) w_[d](a, b) = solution_(row, b);
    }
  }
  for (int i : patch_) local_[static_cast<size_t>(i)] = -1;
  return ok;
}

}  // namespace vdm
