#pragma once
// The three per-axis matrices K^x, K^y, K^z on their shared symmetric sparsity pattern,
// stored together: one index array, the three values of an entry side by side. Kernels work
// on blocks of W = 3 G vectors stored node-major (entry (i, c) at [i * W + c]), G vectors per
// axis side by side: vector c belongs to axis axis_of<W>(c) = c / G (W = 6: r^x s^x r^y s^y
// r^z s^z). One pass over the indices then serves three (or six: the displacement and the
// pressure response) right-hand sides, the G vectors of an axis share each matrix value
// (one SIMD multiply), and the independent dependency chains overlap in the triangular
// solves.
#include <array>
#include <vector>

#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {

struct AxisMatrices {
  int n = 0;
  std::vector<int> start;      // n + 1: row i's off-diagonal entries are [start[i], start[i+1])
  std::vector<int> col;        // their columns, ascending
  std::vector<double> off;     // 3 values per off-diagonal entry (x, y, z)
  std::vector<double> diag;    // 3 values per row
  std::vector<int> off_src;    // index of each off-diagonal entry in the source matrices' values
  std::vector<int> diag_src;   // index of each diagonal entry in the source matrices' values
                               // (both empty when analysed from a StiffnessPattern)
  std::vector<int> off_edge;   // the edge of each off-diagonal entry (analysed from a StiffnessPattern)
  std::vector<int> row_of;     // row v of the source is row row_of[v] here
  std::vector<std::uint8_t> row_mask;  // gather(): 3 per row, the constrained entries
  std::vector<int> held_rows;  // gather(): the rows with a constrained entry

  // Pattern of `pattern` (symmetric, diagonal present) with rows and columns renumbered:
  // row i here is row perm[i] of `pattern` (perm empty: the identity). Values are zero.
  void analyze(const SpMat& pattern, const std::vector<int>& perm);
  // The same for the pattern of an AxisStiffness (gathered by the second gather()).
  void analyze(const StiffnessPattern& pattern, const std::vector<int>& perm);
  // Values from K[0..2] (the SpMat pattern analysed, not a StiffnessPattern; no allocation).
  void gather(const std::array<SpMat, 3>& K);
  // Values from K (the StiffnessPattern analysed; no allocation), with the entries
  // constrained by `mask` (N x 3, source numbering) eliminated: their rows and columns become
  // the identity; `springs` (N x 3, may be null) added to the free diagonal entries.
  void gather(const AxisStiffness& K, const FlagMat& mask, const NodeMat* springs);
};

// The axis of vector c in a block of W.
template <int W>
constexpr int axis_of(int c) {
  return c / (W / 3);
}

// y = K x for a block of W vectors (W = 3 or 6); also dot[c] = x_c . y_c.
template <int W>
void multiply_block(const AxisMatrices& K, const double* x, double* y, double* dot);

}  // namespace vdm
