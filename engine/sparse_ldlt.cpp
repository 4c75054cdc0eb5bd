#include "engine/sparse_ldlt.hpp"

#include <Eigen/OrderingMethods>
#include <cmath>

namespace vdm {

void SparseLdlt::analyze(const SpMat& A) {
  n_ = static_cast<int>(A.cols());
  // Fill-reducing ordering. Eigen's ordering returns the permutation that maps a new index
  // to the old one.
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> new_to_old;
  Eigen::AMDOrdering<int> amd;
  amd(A, new_to_old);
  perm_.assign(new_to_old.indices().data(), new_to_old.indices().data() + n_);
  iperm_.assign(n_, 0);
  for (int k = 0; k < n_; ++k) iperm_[perm_[k]] = k;

  // Elimination tree and column counts of L.
  const int* ap = A.outerIndexPtr();
  const int* ai = A.innerIndexPtr();
  parent_.assign(n_, -1);
  lnz_.assign(n_, 0);
  flag_.assign(n_, -1);
  for (int k = 0; k < n_; ++k) {
    flag_[k] = k;
    const int old = perm_[k];
    for (int p = ap[old]; p < ap[old + 1]; ++p) {
      int i = iperm_[ai[p]];
      if (i >= k) continue;
      // Walk up the tree from i until a node already marked for row k.
      for (; flag_[i] != k; i = parent_[i]) {
        if (parent_[i] == -1) parent_[i] = k;
        ++lnz_[i];
        flag_[i] = k;
      }
    }
  }
  lp_.assign(n_ + 1, 0);
  for (int k = 0; k < n_; ++k) lp_[k + 1] = lp_[k] + lnz_[k];
  li_.assign(lp_[n_], 0);
  lx_.assign(lp_[n_], 0.0);
  d_.assign(n_, 0.0);
  y_.assign(n_, 0.0);
  pattern_.assign(n_, 0);
  work_.assign(n_, 0.0);
}

bool SparseLdlt::factorize(const SpMat& A) {
  const int* ap = A.outerIndexPtr();
  const int* ai = A.innerIndexPtr();
  const double* ax = A.valuePtr();
  bool ok = true;
  for (int k = 0; k < n_; ++k) {
    // Scatter column k of the permuted upper triangle into y; find the pattern of row k of L.
    y_[k] = 0.0;
    int top = n_;
    flag_[k] = k;
    lnz_[k] = 0;
    const int old = perm_[k];
    for (int p = ap[old]; p < ap[old + 1]; ++p) {
      int i = iperm_[ai[p]];
      if (i > k) continue;
      y_[i] += ax[p];
      int len = 0;
      for (; flag_[i] != k; i = parent_[i]) {
        pattern_[len++] = i;
        flag_[i] = k;
      }
      while (len > 0) pattern_[--top] = pattern_[--len];
    }
    // Sparse triangular solve for row k of L, and the pivot d_k.
    d_[k] = y_[k];
    y_[k] = 0.0;
    for (; top < n_; ++top) {
      const int i = pattern_[top];
      const double yi = y_[i];
      y_[i] = 0.0;
      const int end = lp_[i] + lnz_[i];
      for (int p = lp_[i]; p < end; ++p) y_[li_[p]] -= lx_[p] * yi;
      const double lki = yi / d_[i];
      d_[k] -= lki * yi;
      li_[end] = k;
      lx_[end] = lki;
      ++lnz_[i];
    }
    if (!(std::abs(d_[k]) > 0.0) || !std::isfinite(d_[k])) ok = false;
  }
  return ok;
}

void SparseLdlt::solve(const double* b, double* x) const {
  double* w = work_.data();
  for (int k = 0; k < n_; ++k) w[k] = b[perm_[k]];
  for (int j = 0; j < n_; ++j)  // L w = b
    for (int p = lp_[j]; p < lp_[j + 1]; ++p) w[li_[p]] -= lx_[p] * w[j];
  for (int j = 0; j < n_; ++j) w[j] /= d_[j];
  for (int j = n_ - 1; j >= 0; --j)  // L^T w = w
    for (int p = lp_[j]; p < lp_[j + 1]; ++p) w[j] -= lx_[p] * w[li_[p]];
  for (int k = 0; k < n_; ++k) x[perm_[k]] = w[k];
}

}  // namespace vdm
