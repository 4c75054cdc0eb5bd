#pragma once
// The membrane capsule's rest-surface data (TissueModel::membrane_frames and
// membrane_inverse_areas), computed once when the model is built; the per-step strain and
// stress that read them are in engine/membrane_strain.hpp.
#include <vector>

#include "engine/types.hpp"

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
// 0 for a node in no triangle of positive area): the weights of the strain's nodal mean
// (engine/membrane_strain.hpp), fixed with the rest surface.
Vec membrane_inverse_areas(const SurfaceMesh& rest, const std::vector<double>& frames);

}  // namespace vdm
