#pragma once
// The membrane capsule's stress (docs/model.md, "stress"): the skin's in-plane Green strain from
// each triangle's deformation gradient, averaged to the nodes by area, times B_ij. A strain is
// a property of the continuum, not of the mesh: on an irregular surface it stays where the
// tissue is stretched (under and around an instrument), where the capsule's force per node
// would follow the triangulation.
#include "engine/membrane_frames.hpp"
#include "engine/sim_state.hpp"

namespace vdm {

// E_i: the area-weighted mean over node i's triangles of the world-frame Green strain
// ½ (Fᵀ F − I) pushed to 3D by the rest basis (E3 = P E2 Pᵀ, P = [e1 e2]); its diagonal
// (per axis d) at the displacement `u` (N x 3, from rest) is written to `strain_dd` (N x 3,
// dimensionless). `scratch`: 4 N doubles.
void membrane_axis_strain(const TissueModel& model, const NodeMat& u, NodeMat& strain_dd, double* scratch);

// s.stress(i, d) += B_ij E_i,dd at every node (the membrane's stress in pascals: its
// tension T = B_ij V_0/A_0 times the strain, over the organ's length scale V_0/A_0).
// `scratch`: 4 N doubles.
void add_membrane_stress(const TissueModel& model, SimState& state, double* scratch);

}  // namespace vdm
