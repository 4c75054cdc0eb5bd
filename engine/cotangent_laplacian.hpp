#pragma once
// The surface Laplacian of the membrane capsule (docs/model.md, "the capsule"): cotangent
// weights of the rest surface's triangles, or of its intrinsic Delaunay triangulation.
//
// The cotangent Laplacian is the linear finite-element discretisation of the Dirichlet energy
// ½ ∫ |∇u|² dA on a triangle surface, so it converges under refinement; on an obtuse triangle
// a weight goes negative, and the discrete operator then loses the maximum principle (dents
// that pull their neighbours outward, folds on slivers). The intrinsic Delaunay triangulation
// of the same surface (same metric: edge lengths; edges flipped, never moving a node) has
// every weight >= 0 and discretises the same energy. Its edges may join nodes that share no
// mesh edge; an edge from a node to itself (possible on intrinsic triangulations) adds nothing
// to a Laplacian and is dropped; two edges joining the same pair add their weights.
#include <array>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

struct CotangentWeights {
  std::vector<std::array<int, 2>> edges;  // unique pairs i < j, sorted
  std::vector<double> weights;            // w_ij = ½ (cot α + cot β) >= 0 (dimensionless)
  int flips = 0;                          // edges flipped to make the triangulation Delaunay
};

// The weights of the closed, manifold surface (`positions`, `triangles`): with `delaunay`
// false, the plain cotangent weights of the mesh's own edges (negative across an edge whose
// opposite angles sum past pi); with `delaunay`, those of its intrinsic Delaunay triangulation.
CotangentWeights cotangent_weights(const NodeMat& positions, const TriMat& triangles, bool delaunay);

}  // namespace vdm
