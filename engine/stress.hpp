#pragma once
// Per-axis strain and stress (vdm-model.md section 7, paper eqs 5-6).
#include "engine/sim_state.hpp"

namespace vdm {

// eps_i^d   = dV_i^d / V_i with dV_i^d = A_i^d u_i^d
// sigma_i^d = B_i^d eps_i^d + the capsule's term (Pa):
//   membrane capsules: B_ij E_i,dd, the skin's Green strain (membrane_strain.hpp);
//   the paper's:       sum_j B_ij (dV_i^d - dV_j^d) / V_i, eq (6).
// For an infinite B_i^d the bulk term is the constraint force over the patch area,
// -reaction_i^d / A_i^d: the same quantity, B eps = bulk force / A^d, for a finite B.
// `scratch`: 4 N doubles to work in (the step lends an array it is done with). No allocation.
void compute_strain_stress(const TissueModel& model, SimState& state, double* scratch);

}  // namespace vdm
