#pragma once
// The capsule's thin-shell bending term (docs/model.md, "Bending"; vdm-model.md section 3b):
//
//   E_b = ½ D Σ_i |(C u)_i|² / M_i,    K_b = D C M⁻¹ C   (the same matrix on every axis)
//
// with C the cotangent Laplacian of the rest surface (unit tension, C_ij = −c_ij, C_ii =
// Σ_j c_ij) and M_i the node's barycentric rest area. (C u)_i / M_i is the surface Laplacian
// of u at node i, so E_b discretises ½ D ∫ |Δ_S u|² dA: it resists a change of the surface's
// curvature (a bend), where the membrane resists its stretch, and it converges under mesh
// refinement as the membrane does. D is in N·m.
//
// K_b's rows sum to zero (C 1 = 0), so it is a Laplacian of the graph of pairs at most two
// edges apart with weights w_ij = −(K_b)_ij of either sign: it adds to the membrane's edge
// weights (T c_ij) on the union of the two pair sets, and the step's matrices keep their
// form (weights per pair, diagonal = their sums + bulk).
#include <array>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

struct CapsulePairs {
  std::vector<std::array<int, 2>> edges;  // unique pairs i < j, sorted: the edges and the two-ring pairs
  std::vector<double> cot;                // the unit cotangent weight c_ij on each pair (0 off the edges)
  std::vector<double> bending;            // the bending term's weight −(K_b)_ij (N/m)
};

// The Laplacian's pairs `edges` (i < j, sorted) with their unit cotangent weights `cot`,
// joined by the bending term of modulus `D` (N·m) with the nodes' barycentric rest areas
// `area` (M_i = Σ_{t∋i} |t| / 3, m²; the model has them from membrane_inverse_areas).
CapsulePairs capsule_bending_pairs(const std::vector<std::array<int, 2>>& edges, const std::vector<double>& cot,
                                   const Vec& area, double D);

}  // namespace vdm
