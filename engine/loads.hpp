#pragma once
// External loads of the VDM model (vdm-model.md section 3).
#include "engine/tissue_model.hpp"

namespace vdm {

// Hydrostatic gravity, eq (9): f_i += rho g delta_i A_i, delta_i = depth of node i below the
// highest node along gravity. Over a closed surface the sum is the organ's weight rho V g.
// `height` is N scratch.
void add_hydrostatic_loads(const TissueModel& model, const NodeMat& x, const NodeMat& area_vectors,
                           Vec& height, NodeMat& force);

}  // namespace vdm
