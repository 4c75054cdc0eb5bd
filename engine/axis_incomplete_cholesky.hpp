#pragma once
// Zero-fill incomplete Cholesky of the three per-axis matrices at once (AxisMatrices: one
// pattern, one value per entry and a constrained set per axis), K^d ~ L^d (L^d)^T (three
// values per entry of L). With omega = 0 the same factorisation
// as IncompleteCholesky, per axis; with omega > 0 the modified one (see factorize()). The
// index work is shared, and apply() solves a block of W vectors (vector c with axis
// axis_of<W>(c)) in one forward and one backward sweep. analyze() allocates; factorize()
// and apply() do not.
#include <vector>

#include "engine/axis_matrices.hpp"

namespace vdm {

class AxisIncompleteCholesky {
 public:
  void analyze(const AxisMatrices& K);
  // Factorisation on K's pattern. omega = 0: IC(0), fill-in outside the pattern dropped;
  // omega in (0, 1]: relaxed modified IC(0), the fill-in times omega taken off the diagonals
  // instead (omega = 1: L L^T has K's row sums, MIC(0)), a stronger preconditioner for a
  // Laplacian plus a diagonal. Returns the number of pivots (over the three axes) that were
  // not positive and had to be replaced (0 for M-matrices at omega = 0).
  // `compensate`: the positive off-diagonal entries are moved onto the diagonals first (K +
  // k_ij (e_i - e_j)(e_i - e_j)^T for each: a diagonally dominant M-matrix, spectrally above
  // K), for a matrix far from an M-matrix (the capsule's bending term, whose two-ring pairs are
  // positive), where the factorisation of K itself meets pivots near zero and overflows.
  int factorize(const AxisMatrices& K, double omega = 0.0, bool compensate = false);
  // The factors of the last factorize() fitted to the constrained set of K (its row_mask,
  // from gather()) without factorising again: the entries constrained now but not then get
  // the identity's row and column (as factorize() would give them), the entries freed since
  // get K's diagonal alone (a Jacobi row; their row and column were the identity's). L stays
  // lower triangular with a positive diagonal, so L L^T is SPD: a valid preconditioner, made
  // from older matrices. Returns the number of entries changed.
  int fit_to_mask(const AxisMatrices& K);
  // z = (L L^T)^{-1} r on a block of W vectors; also rz[c] = r_c . z_c. With `live` (W
  // values), vector c's r is taken as zero where live[c] is 0 (the same bits as zeroing it
  // first: block_pcg's stopped columns, whose r is left as it is).
  template <int W>
  void apply(const double* r, double* z, double* rz, const double* live = nullptr) const;
  // The same for one vector of axis d alone, stored contiguously (a column taken out of a
  // block), with apply()'s operations on a lane of axis d in its order: the same values bit
  // for bit. Returns r . z.
  double apply_axis(int d, const double* r, double* z) const;
  int size() const { return n_; }
  // The factors' values and constrained set, for state snapshots: appended to `out`; read
  // back from `in` at `pos` (advanced) after analyze() of the same pattern. False when `in`
  // is too short.
  void save_values(std::vector<double>& out) const;
  bool load_values(const std::vector<double>& in, size_t& pos);

 private:
  int n_ = 0;
  // Strictly lower part of L by rows (the columns of K's row i below i, ascending);
  // source: index of the entry among K's off-diagonal entries. (The sweeps take 6 x col for
  // block_row: copies of the columns times 6 saved 8 % of their instructions but cost 1 MB at
  // 40k nodes, which the peak-memory target did not have.)
  std::vector<int> lo_start_, lo_col_, lo_src_;
  std::vector<float> lo_val_;              // 3 per entry (float: a preconditioner; half the loads),
                                           // and one to spare (the AVX2 sweeps read 4 at a time)
  // The same entries by rows of L^T (strictly upper), for a gathering backward solve;
  // up_src_: index into the lower entries.
  std::vector<int> up_start_, up_col_, up_src_;
  std::vector<float> up_val_;              // 3 per entry, and one to spare
  std::vector<double> inv_diag_;           // 3 per row: 1 / L_ii
  std::vector<std::uint8_t> mask_;         // 3 per row: the constrained set the factors fit
  std::vector<double> work_diag_;           // scratch: K's diagonal as the elimination updates it
  std::vector<int> update_target_;           // factorize(): the L entry of each update, or -1
  void copy_to_upper();                      // up_val_ from lo_val_
};

}  // namespace vdm
