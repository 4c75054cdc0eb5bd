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
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

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
  double at(int d, int a, int b) const { return w_[d](a, b); }
  int patch_size() const { return static_cast<int>(patch_.size()); }

 private:
  std::vector<int> patch_;  // the patch's nodes (the contact nodes first)
  std::vector<int> local_;  // N: a node's index in patch_, or -1
  std::vector<Eigen::Triplet<double>> triplets_;
  std::vector<int> unknown_;  // per patch node: its row in this axis's system, or -1 (fixed)
  SpMat matrix_;
  Eigen::SimplicialLDLT<SpMat> ldlt_;
  Eigen::MatrixXd rhs_, solution_;
  Eigen::MatrixXd w_[3];
};

}  // namespace vdm
