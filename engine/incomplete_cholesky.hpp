#pragma once
// Zero-fill incomplete Cholesky, K ~ L L^T, on the pattern of K. K^d is a Laplacian plus a
// positive diagonal (an M-matrix), for which IC(0) exists and is a strong CG preconditioner.
// The pattern is analysed once; factorize() and apply() allocate nothing.
#include <vector>

#include "engine/sparse.hpp"

namespace vdm {

class IncompleteCholesky {
 public:
  // Sets up the lower-triangular pattern from the symmetric pattern of K.
  void analyze(const SpMat& K);
  // Numeric factorisation of K (same pattern as analysed). Returns the number of pivots
  // that were not positive and had to be replaced (0 for an M-matrix).
  int factorize(const SpMat& K);
  // z = (L L^T)^{-1} r.
  void apply(const double* r, double* z) const;
  int size() const { return n_; }

 private:
  int n_ = 0;
  std::vector<int> row_start_;   // CSR of L: row i holds columns <= i, sorted, diagonal last
  std::vector<int> col_;
  std::vector<int> source_;      // index of each L entry in K's value array
  std::vector<double> val_;
  // L^T by rows (the strictly upper part), so that the backward solve gathers too.
  std::vector<int> up_start_, up_col_, up_source_;  // up_source_: index into val_
  std::vector<double> up_val_, inv_diag_;
  std::vector<int> marker_;      // scratch: position of column j in the current row, or -1
};

}  // namespace vdm
