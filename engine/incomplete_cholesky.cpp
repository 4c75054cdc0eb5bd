#include "engine/incomplete_cholesky.hpp"

#include <cmath>

namespace vdm {

void IncompleteCholesky::analyze(const SpMat& K) {
  n_ = static_cast<int>(K.cols());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  // Row i of the lower triangle = entries of column i with row index <= i (K symmetric).
  row_start_.assign(n_ + 1, 0);
  col_.clear();
  source_.clear();
  for (int i = 0; i < n_; ++i) {
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] <= i) {  // inner indices are sorted, so the diagonal comes last
        col_.push_back(inner[k]);
        source_.push_back(k);
      }
    row_start_[i + 1] = static_cast<int>(col_.size());
  }
  val_.assign(col_.size(), 0.0);
  marker_.assign(n_, -1);
  // Rows of L^T: entry (i, k) of L with k < i is entry (k, i) of L^T.
  up_start_.assign(n_ + 1, 0);
  for (int i = 0; i < n_; ++i)
    for (int p = row_start_[i]; p < row_start_[i + 1] - 1; ++p) ++up_start_[col_[p] + 1];
  for (int k = 0; k < n_; ++k) up_start_[k + 1] += up_start_[k];
  up_col_.assign(up_start_[n_], 0);
  up_source_.assign(up_start_[n_], 0);
  std::vector<int> fill(up_start_.begin(), up_start_.end() - 1);
  for (int i = 0; i < n_; ++i)
    for (int p = row_start_[i]; p < row_start_[i + 1] - 1; ++p) {
      const int k = col_[p];
      up_col_[fill[k]] = i;
      up_source_[fill[k]++] = p;
    }
  up_val_.assign(up_start_[n_], 0.0);
  inv_diag_.assign(n_, 0.0);
}

int IncompleteCholesky::factorize(const SpMat& K) {
  const double* a = K.valuePtr();
  int repaired = 0;
  for (int i = 0; i < n_; ++i) {
    const int begin = row_start_[i], end = row_start_[i + 1];
    for (int p = begin; p < end; ++p) marker_[col_[p]] = p;
    double diag_sum = 0.0;
    for (int p = begin; p < end - 1; ++p) {
      const int k = col_[p];
      double s = a[source_[p]];
      // subtract sum_{j<k} L_ij L_kj over the shared pattern
      for (int q = row_start_[k]; q < row_start_[k + 1] - 1; ++q) {
        const int m = marker_[col_[q]];
        if (m >= 0 && m < p) s -= val_[m] * val_[q];
      }
      val_[p] = s / val_[row_start_[k + 1] - 1];
      diag_sum += val_[p] * val_[p];
    }
    const double aii = a[source_[end - 1]];
    double d = aii - diag_sum;
    if (!(d > 1e-12 * std::abs(aii))) {
      d = std::abs(aii) > 0 ? std::abs(aii) : 1.0;
      ++repaired;
    }
    val_[end - 1] = std::sqrt(d);
    inv_diag_[i] = 1.0 / val_[end - 1];
    for (int p = begin; p < end; ++p) marker_[col_[p]] = -1;
  }
  for (size_t q = 0; q < up_val_.size(); ++q) up_val_[q] = val_[up_source_[q]];
  return repaired;
}

void IncompleteCholesky::apply(const double* r, double* z) const {
  // Forward: L y = r (y stored in z).
  for (int i = 0; i < n_; ++i) {
    double s = r[i];
    const int end = row_start_[i + 1] - 1;
    for (int p = row_start_[i]; p < end; ++p) s -= val_[p] * z[col_[p]];
    z[i] = s * inv_diag_[i];
  }
  // Backward: L^T z = y, by the rows of L^T (a gather like the forward solve).
  for (int i = n_ - 1; i >= 0; --i) {
    double s = z[i];
    for (int p = up_start_[i]; p < up_start_[i + 1]; ++p) s -= up_val_[p] * z[up_col_[p]];
    z[i] = s * inv_diag_[i];
  }
}

}  // namespace vdm
