#pragma once
// Assembly of the per-axis stiffness K^d = L_w + diag(k^d) (vdm-model.md section 3) into the
// fixed pattern, and per-axis elimination of constrained entries (Dirichlet rows/columns).
#include <array>

#include "engine/sparse.hpp"
#include "engine/tissue_model.hpp"

namespace vdm {

// Writes K^d for d = x, y, z at the geometry (A_i, V_i) into K[d] (values only; the matrices
// must already carry `model.pattern`). `extra_diagonal` (N, may be empty) is added to every
// axis: the inertia term M/h^2 + D/h.
//   bulk:          k_i^d = B_i^d (A_i^d)^2 / V_i                          eq (3)
//   connectivity:  w_ij  = B_ij a_ij^2 / V_ij, a_ij = (|A_i|+|A_j|)/2, V_ij = (V_i+V_j)/2   eq (4)
void assemble_stiffness(const TissueModel& model, const NodeMat& area_vectors,
                        const Vec& node_volumes, const Vec& extra_diagonal,
                        std::array<SpMat, 3>& K);
// The same with the lengths |A_i| given (`area_norms`, N) and `scratch` (N) to work in: no
// allocation, every value written once (the step's).
void assemble_stiffness(const TissueModel& model, const NodeMat& area_vectors, const Vec& area_norms,
                        const Vec& node_volumes, const Vec& extra_diagonal, std::array<SpMat, 3>& K,
                        Vec& scratch);

// K_masked = K with rows and columns of constrained nodes (mask(i) != 0) replaced by the
// identity, and spring[i] (when given) added to the free diagonal entries. Same pattern,
// values written in place.
void mask_constrained(const SpMat& K, const std::uint8_t* mask, SpMat& K_masked, const double* spring = nullptr);

// Right-hand side of the eliminated system on one axis: rhs_i = f_i - sum_{j constrained}
// K_ij u_j for free i, rhs_j = u_j for constrained j.
void eliminate_rhs(const SpMat& K, const std::uint8_t* mask, const double* f, const double* u_fixed,
                   double* rhs);

// y = K x for the symmetric K.
void symmetric_multiply(const SpMat& K, const double* x, double* y);

// y_i = (K x)_i for the rows with rows[i] != 0 (symmetric K); other entries of y untouched.
void symmetric_multiply_rows(const SpMat& K, const std::uint8_t* rows, const double* x, double* y);

}  // namespace vdm
