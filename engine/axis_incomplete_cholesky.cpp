#include "engine/axis_incomplete_cholesky.hpp"

#include <cmath>

namespace vdm {

void AxisIncompleteCholesky::analyze(const AxisMatrices& K) {
  n_ = K.n;
  lo_start_.assign(size_t(n_) + 1, 0);
  lo_col_.clear();
  lo_src_.clear();
  for (int i = 0; i < n_; ++i) {
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p)
      if (K.col[size_t(p)] < i) {  // columns ascending: the lower ones come first
        lo_col_.push_back(K.col[size_t(p)]);
        lo_src_.push_back(p);
      }
    lo_start_[size_t(i) + 1] = static_cast<int>(lo_col_.size());
  }
  lo_val_.assign(3 * lo_col_.size(), 0.0);
  // Rows of L^T: entry (i, k) of L with k < i is entry (k, i) of L^T.
  up_start_.assign(size_t(n_) + 1, 0);
  for (size_t p = 0; p < lo_col_.size(); ++p) ++up_start_[size_t(lo_col_[p]) + 1];
  for (int k = 0; k < n_; ++k) up_start_[size_t(k) + 1] += up_start_[size_t(k)];
  up_col_.assign(lo_col_.size(), 0);
  up_src_.assign(lo_col_.size(), 0);
  std::vector<int> fill(up_start_.begin(), up_start_.end() - 1);
  for (int i = 0; i < n_; ++i)
    for (int p = lo_start_[size_t(i)]; p < lo_start_[size_t(i) + 1]; ++p) {
      const int k = lo_col_[size_t(p)];
      up_col_[size_t(fill[size_t(k)])] = i;
      up_src_[size_t(fill[size_t(k)]++)] = p;
    }
  up_val_.assign(3 * lo_col_.size(), 0.0);
  inv_diag_.assign(3 * size_t(n_), 0.0);
  marker_.assign(size_t(n_), -1);
}

int AxisIncompleteCholesky::factorize(const AxisMatrices& K) {
  int repaired = 0;
  double* L = lo_val_.data();
  for (int i = 0; i < n_; ++i) {
    const int begin = lo_start_[size_t(i)], end = lo_start_[size_t(i) + 1];
    for (int p = begin; p < end; ++p) marker_[size_t(lo_col_[size_t(p)])] = p;
    double diag_sum[3] = {0.0, 0.0, 0.0};
    for (int p = begin; p < end; ++p) {
      const int k = lo_col_[size_t(p)];
      const double* a = &K.off[3 * size_t(lo_src_[size_t(p)])];
      double s[3] = {a[0], a[1], a[2]};
      // subtract sum_{j<k} L_ij L_kj over the shared pattern (row k's columns are all < k,
      // so a column of row i found there lies before p)
      for (int q = lo_start_[size_t(k)]; q < lo_start_[size_t(k) + 1]; ++q) {
        const int m = marker_[size_t(lo_col_[size_t(q)])];
        if (m >= 0)
          for (int d = 0; d < 3; ++d) s[d] -= L[3 * size_t(m) + size_t(d)] * L[3 * size_t(q) + size_t(d)];
      }
      for (int d = 0; d < 3; ++d) {
        const double v = s[d] * inv_diag_[3 * size_t(k) + size_t(d)];
        L[3 * size_t(p) + size_t(d)] = v;
        diag_sum[d] += v * v;
      }
    }
    for (int d = 0; d < 3; ++d) {
      const double aii = K.diag[3 * size_t(i) + size_t(d)];
      double piv = aii - diag_sum[d];
      if (!(piv > 1e-12 * std::abs(aii))) {
        piv = std::abs(aii) > 0 ? std::abs(aii) : 1.0;
        ++repaired;
      }
      inv_diag_[3 * size_t(i) + size_t(d)] = 1.0 / std::sqrt(piv);
    }
    for (int p = begin; p < end; ++p) marker_[size_t(lo_col_[size_t(p)])] = -1;
  }
  for (size_t q = 0; q < up_src_.size(); ++q)
    for (size_t d = 0; d < 3; ++d) up_val_[3 * q + d] = L[3 * size_t(up_src_[q]) + d];
  return repaired;
}

template <int W>
void AxisIncompleteCholesky::apply(const double* r, double* z, double* rz) const {
  static_assert(W % 3 == 0, "blocks of whole axis triples");
  const int* lo_start = lo_start_.data();
  const int* lo_col = lo_col_.data();
  const double* lo_val = lo_val_.data();
  const double* inv_diag = inv_diag_.data();
  // Forward: L y = r (y stored in z).
  for (int i = 0; i < n_; ++i) {
    double acc[W];
    for (int c = 0; c < W; ++c) acc[c] = r[size_t(i) * W + c];
    for (int p = lo_start[i]; p < lo_start[i + 1]; ++p) {
      const double* v = lo_val + 3 * size_t(p);
      const double* zj = z + size_t(lo_col[p]) * W;
      for (int c = 0; c < W; ++c) acc[c] -= v[c % 3] * zj[c];
    }
    for (int c = 0; c < W; ++c) z[size_t(i) * W + c] = acc[c] * inv_diag[3 * size_t(i) + c % 3];
  }
  // Backward: L^T z = y, by the rows of L^T (a gather like the forward solve).
  const int* up_start = up_start_.data();
  const int* up_col = up_col_.data();
  const double* up_val = up_val_.data();
  double dot[W] = {};
  for (int i = n_ - 1; i >= 0; --i) {
    double acc[W];
    for (int c = 0; c < W; ++c) acc[c] = z[size_t(i) * W + c];
    for (int p = up_start[i]; p < up_start[i + 1]; ++p) {
      const double* v = up_val + 3 * size_t(p);
      const double* zj = z + size_t(up_col[p]) * W;
      for (int c = 0; c < W; ++c) acc[c] -= v[c % 3] * zj[c];
    }
    for (int c = 0; c < W; ++c) {
      const double zi = acc[c] * inv_diag[3 * size_t(i) + c % 3];
      z[size_t(i) * W + c] = zi;
      dot[c] += r[size_t(i) * W + c] * zi;
    }
  }
  for (int c = 0; c < W; ++c) rz[c] = dot[c];
}

template void AxisIncompleteCholesky::apply<3>(const double*, double*, double*) const;
template void AxisIncompleteCholesky::apply<6>(const double*, double*, double*) const;

}  // namespace vdm
