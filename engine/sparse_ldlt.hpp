#pragma once
// Sparse LDL^T for the per-axis SPD matrices, written so that refactorisation and solves
// allocate nothing: the fill-reducing ordering (AMD), the elimination tree and the pattern of
// L are computed once by analyze(); factorize() and solve() reuse those arrays.
// Up-looking algorithm: row k of L comes from a sparse triangular solve with the rows above,
// its pattern found by walking the elimination tree from the entries of column k of A.
#include <vector>

#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {

class SparseLdlt {
 public:
  // A: symmetric pattern, both triangles stored (as the stiffness pattern is).
  void analyze(const SpMat& A);
  // Numeric factorisation of A (same pattern). False if a pivot is zero or not finite.
  bool factorize(const SpMat& A);
  // x = A^{-1} b. `x` may alias nothing; sized N.
  void solve(const double* b, double* x) const;
  long factor_nonzeros() const { return static_cast<long>(li_.size()); }

 private:
  int n_ = 0;
  std::vector<int> perm_;     // new index -> old index
  std::vector<int> iperm_;    // old index -> new index
  std::vector<int> parent_;   // elimination tree
  std::vector<int> lp_;       // column starts of L (strictly lower, unit diagonal implied)
  std::vector<int> li_;       // row indices of L
  std::vector<double> lx_;    // values of L
  std::vector<double> d_;     // diagonal D
  // scratch
  std::vector<int> lnz_, flag_, pattern_;
  std::vector<double> y_;
  mutable std::vector<double> work_;
};

}  // namespace vdm
