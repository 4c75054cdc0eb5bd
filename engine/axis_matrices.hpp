#pragma once
// The three per-axis matrices K^x, K^y, K^z on their shared symmetric sparsity pattern,
// stored together: one index array and one value per off-diagonal entry for the three axes
// (K^d = the shared edge Laplacian, its rows and columns of the constrained entries of axis
// d replaced by the identity's), three diagonal values per row. Kernels work on blocks of
// W = 3 G vectors stored node-major (entry (i, c) at [i * W + c]), G vectors per axis side
// by side: vector c belongs to axis axis_of<W>(c) = c / G (W = 6: r^x s^x r^y s^y r^z s^z).
// One pass over the indices and values then serves three (or six: the displacement and the
// pressure response) right-hand sides, and the independent dependency chains overlap in the
// triangular solves.
#include <array>
#include <type_traits>
#include <vector>

#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {

struct AxisMatrices {
  int n = 0;
  std::vector<int> start;      // n + 1: row i's off-diagonal entries are [start[i], start[i+1])
  std::vector<int> col6;       // 6 x their columns (ascending): the column's row in a block of
                               // 6 (block_row), for the kernels; column() for the column itself
  std::vector<double> off;     // 1 value per off-diagonal entry for the three axes, 0 in the
                               // rows and columns of the rows constrained on every axis
  std::vector<double> diag;    // 3 values per row (1 for a constrained entry)
  std::vector<int> off_edge;   // the edge of each off-diagonal entry
  std::vector<int> row_of;     // row v of the source is row row_of[v] here
  std::vector<int> node_of;    // and row i here row node_of[i] of the source
  std::vector<std::uint8_t> row_mask;  // gather(): 3 per row, the constrained entries
  std::vector<int> held_rows;  // gather(): first the rows constrained on some axes only
  int partial_count = 0;       // (partial_count of them), the rows constrained on all at the end
  int full_count = 0;          // (full_count of them)
  std::vector<int> zeroed;     // gather(): the entries zeroed for the rows constrained on all
  FlagMat gathered_mask;       // the mask those were made for (source numbering)

  // The column of off-diagonal entry p (only col6 is kept: 1 MB less at 40k nodes).
  int column(size_t p) const { return col6[p] / 6; }
  // Entry (i, j != i) of K^d: off[p] unless entry d of row i or row j is constrained.
  bool constrained(int i, int d) const { return row_mask[3 * size_t(i) + size_t(d)] != 0; }

  // The pattern of an AxisStiffness with rows and columns renumbered: row i here is row
  // perm[i] of `pattern` (perm empty: the identity). Values are zero, nothing constrained.
  void analyze(const StiffnessPattern& pattern, const std::vector<int>& perm);
  // Values from K (the StiffnessPattern analysed; no allocation), with the entries
  // constrained by `mask` (N x 3, source numbering) eliminated: their rows and columns become
  // the identity; `springs` (N x 3, may be null) added to the free diagonal entries.
  // Most gathers see the mask of the last one: only the values are copied then.
  void gather(const AxisStiffness& K, const FlagMat& mask, const NodeMat* springs);

 private:
  void classify(const FlagMat& mask);  // row_mask, held_rows, the counts, zeroed from mask
};

// Row j of a block of W (W = 3 or 6) from six_j = 6 j: x + 6 j, or x + 3 j as 4 bytes times
// 6 j. One addressing mode, where j W took a multiply and a shift per entry in the kernels.
template <int W, class T>
inline T* block_row(T* x, int six_j) {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  using Byte = std::conditional_t<std::is_const_v<T>, const char, char>;
  return reinterpret_cast<T*>(reinterpret_cast<Byte*>(x) + size_t(six_j) * (W * sizeof(double) / 6));
}

// The axis of vector c in a block of W.
template <int W>
constexpr int axis_of(int c) {
  return c / (W / 3);
}

// y = K x for a block of W vectors (W = 3 or 6), each vector with its axis's matrix (the
// constrained entries' rows and columns the identity's, whatever x holds there); also
// dot[c] = x_c . y_c.
template <int W>
void multiply_block(const AxisMatrices& K, const double* x, double* y, double* dot);
// The residual of a block at the start of a solve, in one pass: r = b - K x (r may be b
// itself: each row of b is read before that row of r is written), bn[c] = |b_c|^2 and
// rn[c] = |r_c|^2, each sum taken row by row from 0 (block_pcg's own passes: the same bits as
// multiply_block followed by those passes). False, and nothing written, when some row is
// constrained on some axes only: the product's fix-up of those rows comes after the pass.
template <int W>
bool residual_block(const AxisMatrices& K, const double* b, const double* x, double* r, double* bn, double* rn);
// The same with b in the source's numbering: system g (of W / 3) an n x 3 column-major
// matrix at b_src[g] (a NodeMat's data), vector c = d (W / 3) + g of the block its column d,
// row i's entries from row node_of[i] (each row read where the pass needs it: no permuted
// copy of b is written and read back). The same bits as with that copy.
template <int W>
bool residual_block(const AxisMatrices& K, const std::array<const double*, W / 3>& b_src, const double* x, double* r,
                    double* bn, double* rn);
// K^d x for one vector of axis d alone, stored contiguously (a column taken out of a
// block): the operations of multiply_block on a lane of axis d, in its order, so the same
// values bit for bit, touching n values of x and y where a column inside the block touches
// every cache line of it. Returns x . y.
double multiply_axis(const AxisMatrices& K, int d, const double* x, double* y);

}  // namespace vdm
