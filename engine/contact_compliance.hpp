#pragma once
// The organ's compliance at a few surface nodes, on a patch around them: W^d_ab, how far node
// a moves along axis d under a unit force on node b along d (the entries of (K^d)^-1). The
// constraint contact uses it as the Jacobian of its Gauss-Seidel on the contact forces.
//
// Why a patch: the exact (K^d)^-1 columns take a solve over the whole surface per node and
// axis. The bulk term anchors the surface, so the response to a point load fades within a
// few edges (over about (V/A) sqrt(B_ij / B)); a few rings of neighbours hold most of it. The
// nodes outside the patch are held. That makes the patch stiffer than the organ where the
// response reaches further (along an axis in which the surface has almost no bulk term: a
// flat face's own plane); the fluid's pressure, left out, makes it softer for pushes into
// the organ. The contact's outer iteration, which solves the whole organ with the forces
// found, corrects both, with a scale fitted to what its first correction moved against
// what the patch predicted. (A free rim, the other choice, leaves the patch floating along
// such axes; measured on a sliding probe it took twice the solves.)
//
// How: the patch's nodes are numbered ring by ring from the contact nodes outward (breadth
// first), so every node's neighbours are in its own ring or the next or last: the patch
// matrix is banded with about a ring's width, and an envelope (skyline) LDL^T factorises it
// without fill outside the envelope and without a fill-reducing ordering. Every array is kept
// between calls, so once the patches have reached their working size nothing is allocated.
#include <vector>

#include "engine/neighbour_lists.hpp"
#include "engine/sparse.hpp"

namespace vdm {

class PatchCompliance {
 public:
  // W for `nodes` (distinct), on the patch of the nodes within `rings` edges of them. K: the
  // per-axis stiffness; `fixed_a`, `fixed_b` (N x 3, each may have 0 rows): entries that do
  // not move (held, driven): their compliance is 0. False when a patch matrix could not be
  // factorised (then `at` gives the inverse diagonal: each node alone).
  bool compute(const NeighbourLists& neighbours, const AxisStiffness& K, const FlagMat& fixed_a,
               const FlagMat& fixed_b, const std::vector<int>& nodes, int rings);
  // W^d between nodes[a] and nodes[b].
  double at(int d, int a, int b) const { return w_[d][static_cast<size_t>(a) * static_cast<size_t>(count_) + b]; }
  int patch_size() const { return static_cast<int>(patch_.size()); }

 private:
  // Factorises the axis-d patch matrix (rows: the patch's unknowns) in place; false if a
  // pivot is not positive.
  bool factorise(int rows);
  std::vector<int> patch_;   // the patch's nodes, ring by ring (the contact nodes first)
  std::vector<int> local_;   // N: a node's index in patch_, or -1
  std::vector<int> unknown_;  // per patch node: its row in this axis's system, or -1 (fixed)
  std::vector<int> node_of_row_;
  // The envelope: row r holds columns first_[r] .. r-1 at env_[start_[r] ...], its diagonal
  // at diag_[r]. After factorise(): L's strictly lower rows and D.
  std::vector<int> first_;
  std::vector<size_t> start_;
  std::vector<double> env_, diag_, work_;
  int count_ = 0;  // contact nodes
  std::vector<double> w_[3];  // count_ x count_, row-major
};

}  // namespace vdm
