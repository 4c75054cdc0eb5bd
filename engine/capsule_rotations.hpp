#pragma once
// The corotational membrane capsule (docs/model.md, "rotation invariance"): the membrane's
// energy ½ Σ_ij w_ij |(x_i − x_j) − R̄_ij (X_i − X_j)|², R̄_ij = (R_i + R_j) / 2, with each
// node's rotation R_i fitted to its neighbourhood (the as-rigid-as-possible local step). A
// rigid rotation of a patch then costs nothing, so a twist or a large bend carries.
//
// With the rotations fixed for a solve, the stiffness is the membrane's Laplacian as before
// and the rotations enter as a load g_i = Σ_j w_ij (R̄_ij − I)(X_i − X_j) (N). With the
// bending term (capsule_bending.hpp) each node's rest curvature turns with it: energy
// ½ D Σ_k |(C x)_k − R_k (C X)_k|² / M_k, whose load is D C h with h_k = (R_k − I)(C X)_k / M_k.
// No allocation.
#include <vector>

#include "engine/tissue_model.hpp"

namespace vdm {

// Rotations, one 3 x 3 matrix per node (column-major): 9 N doubles.
using NodeRotations = std::vector<double>;

// R_i = argmin_R Σ_j w_ij |(x_i − x_j) − R (X_i − X_j)|² for every node, at the positions
// `x` (N x 3). Each fit starts from the identity and turns towards the optimum (the
// polar part of Σ_j w_ij e_ij d_ijᵀ) until the turn is below 1e-10 rad, so the result
// depends on the positions alone. `rotations` must hold 9 N doubles.
void fit_capsule_rotations(const TissueModel& model, const NodeMat& x, NodeRotations& rotations);

// f += g(R): the rotations' load.
void add_corotation_load(const TissueModel& model, const NodeRotations& rotations, NodeMat& f);

}  // namespace vdm
