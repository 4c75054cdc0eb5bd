#pragma once
// The membrane capsule's stress (docs/model.md, "stress"): the skin's in-plane Green strain from
// each triangle's deformation gradient, averaged to the nodes by area, times B_ij. A strain is
// a property of the continuum, not of the mesh: on an irregular surface it stays where the
// tissue is stretched (under and around an instrument), where the capsule's force per node
// would follow the triangulation.
#include <vector>

#include "engine/sim_state.hpp"

namespace vdm {

// Per triangle of the rest surface (TissueModel::membrane_frames): an orthonormal basis
// (e1, e2) of its plane (e1 along its first edge) and the inverse of its edge matrix in that
// basis, [x_b − x_a, x_c − x_a] = D, D⁻¹ (2 x 2, upper triangular as D is: its three entries
// (0,0), (0,1), (1,1)), and its area: 10 fields. Stored four triangles to a block, field by
// field (field k of triangle t at block t / 4, index 4 k + t % 4), so that four triangles'
// fields load as one vector; the last block padded with area 0.
constexpr int kMembraneFrameFields = 10;
constexpr int kMembraneFrameBlock = 4 * kMembraneFrameFields;
std::vector<double> membrane_frames(const SurfaceMesh& rest);
// Per node: 1 / the summed area of its rest triangles (TissueModel::membrane_inverse_areas;
// 0 for a node in no triangle of positive area): the weights of the nodal mean below, fixed
// with the rest surface.
Vec membrane_inverse_areas(const SurfaceMesh& rest, const std::vector<double>& frames);

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
