#include "engine/contact_compliance.hpp"

#include <algorithm>

#include "engine/headroom.hpp"

namespace vdm {

namespace {

bool is_fixed(const FlagMat& f, int i, int d) { return f.rows() > i && f(i, d) != 0; }

}  // namespace

bool PatchCompliance::factorise(int rows) {
  // Row by row: l_rj = (a_rj - sum_k l_rk d_k l_jk) / d_j over the shared envelope, then
  // d_r = a_rr - sum_k l_rk^2 d_k. work_ holds l_rk d_k of the row being factorised.
  for (int r = 0; r < rows; ++r) {
    double* row = env_.data() + start_[static_cast<size_t>(r)];
    const int fr = first_[static_cast<size_t>(r)];
    for (int j = fr; j < r; ++j) {
      const int fj = first_[static_cast<size_t>(j)];
      const double* rj = env_.data() + start_[static_cast<size_t>(j)];
      double sum = row[j - fr];
      for (int k = std::max(fr, fj); k < j; ++k) sum -= work_[static_cast<size_t>(k)] * rj[k - fj];
      work_[static_cast<size_t>(j)] = sum;  // l_rj d_j
      row[j - fr] = sum / diag_[static_cast<size_t>(j)];
    }
    double d = diag_[static_cast<size_t>(r)];
    for (int j = fr; j < r; ++j) d -= work_[static_cast<size_t>(j)] * row[j - fr];
    if (!(d > 0.0)) return false;
    diag_[static_cast<size_t>(r)] = d;
  }
  return true;
}

bool PatchCompliance::compute(const NeighbourLists& nb, const AxisStiffness& K, const FlagMat& fixed_a,
                              const FlagMat& fixed_b, const std::vector<int>& nodes, int rings) {
  const int n = static_cast<int>(K.diagonal.rows());
  if (static_cast<int>(local_.size()) != n) local_.assign(static_cast<size_t>(n), -1);
  // The patch: breadth first from the contact nodes, `rings` deep.
  assign_with_headroom(patch_, nodes.begin(), nodes.end());
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
  count_ = c;
  resize_with_headroom(unknown_, static_cast<size_t>(p));
  resize_with_headroom(node_of_row_, static_cast<size_t>(p));
  resize_with_headroom(first_, static_cast<size_t>(p));
  resize_with_headroom(start_, static_cast<size_t>(p) + 1);
  resize_with_headroom(diag_, static_cast<size_t>(p));
  resize_with_headroom(work_, static_cast<size_t>(p));
  bool ok = true;
  for (int d = 0; d < 3; ++d) {
    std::vector<double>& w = w_[d];
    resize_square_with_headroom(w, static_cast<size_t>(c));
    std::fill(w.begin(), w.end(), 0.0);
    int rows = 0;
    for (int k = 0; k < p; ++k) {
      const bool moves = !is_fixed(fixed_a, patch_[k], d) && !is_fixed(fixed_b, patch_[k], d);
      unknown_[static_cast<size_t>(k)] = moves ? rows : -1;
      if (moves) node_of_row_[static_cast<size_t>(rows++)] = patch_[k];
    }
    if (rows == 0) continue;
    // The envelope of each row: its first neighbour among the unknowns.
    start_[0] = 0;
    for (int r = 0; r < rows; ++r) {
      const int i = node_of_row_[static_cast<size_t>(r)];
      int f = r;
      for (int e = nb.begin[static_cast<size_t>(i)]; e < nb.begin[static_cast<size_t>(i) + 1]; ++e) {
        const int lj = local_[static_cast<size_t>(nb.entries[static_cast<size_t>(e)].node)];
        const int col = lj < 0 ? -1 : unknown_[static_cast<size_t>(lj)];
        if (col >= 0) f = std::min(f, col);
      }
      first_[static_cast<size_t>(r)] = f;
      start_[static_cast<size_t>(r) + 1] = start_[static_cast<size_t>(r)] + static_cast<size_t>(r - f);
    }
    assign_with_headroom(env_, start_[static_cast<size_t>(rows)], 0.0);
    for (int r = 0; r < rows; ++r) {
      const int i = node_of_row_[static_cast<size_t>(r)];
      diag_[static_cast<size_t>(r)] = K.diagonal(i, d);
      double* row = env_.data() + start_[static_cast<size_t>(r)];
      for (int e = nb.begin[static_cast<size_t>(i)]; e < nb.begin[static_cast<size_t>(i) + 1]; ++e) {
        const NeighbourLists::Entry& en = nb.entries[static_cast<size_t>(e)];
        const int lj = local_[static_cast<size_t>(en.node)];
        const int col = lj < 0 ? -1 : unknown_[static_cast<size_t>(lj)];
        if (col >= 0 && col < r) row[col - first_[static_cast<size_t>(r)]] = -K.weight[en.edge];
      }
    }
    if (!factorise(rows)) {
      ok = false;
      for (int a = 0; a < c; ++a)
        if (unknown_[static_cast<size_t>(a)] >= 0)
          w[static_cast<size_t>(a) * static_cast<size_t>(c) + a] = 1.0 / std::max(K.diagonal(nodes[static_cast<size_t>(a)], d), 1e-300);
      continue;
    }
    // Column b of W: solve with a unit load on contact node b (row unknown_[b]); read the
    // contact nodes' rows. The contact nodes come first, so the forward pass starts at b's row.
    for (int b = 0; b < c; ++b) {
      const int rb = unknown_[static_cast<size_t>(b)];
      if (rb < 0) continue;
      std::fill(work_.begin(), work_.begin() + rows, 0.0);
      work_[static_cast<size_t>(rb)] = 1.0;
      for (int r = rb + 1; r < rows; ++r) {  // L y = e_b
        const int fr = first_[static_cast<size_t>(r)];
        const double* row = env_.data() + start_[static_cast<size_t>(r)];
        double sum = 0.0;
        for (int k = std::max(fr, rb); k < r; ++k) sum += row[k - fr] * work_[static_cast<size_t>(k)];
        work_[static_cast<size_t>(r)] = -sum;
      }
      for (int r = rb; r < rows; ++r) work_[static_cast<size_t>(r)] /= diag_[static_cast<size_t>(r)];
      for (int r = rows - 1; r > 0; --r) {  // L^T x = y
        const int fr = first_[static_cast<size_t>(r)];
        const double* row = env_.data() + start_[static_cast<size_t>(r)];
        const double xr = work_[static_cast<size_t>(r)];
        if (xr != 0.0)
          for (int k = fr; k < r; ++k) work_[static_cast<size_t>(k)] -= row[k - fr] * xr;
      }
      for (int a = 0; a < c; ++a) {
        const int ra = unknown_[static_cast<size_t>(a)];
        if (ra >= 0) w[static_cast<size_t>(a) * static_cast<size_t>(c) + b] = work_[static_cast<size_t>(ra)];
      }
    }
  }
  for (int i : patch_) local_[static_cast<size_t>(i)] = -1;
  return ok;
}

}  // namespace vdm
