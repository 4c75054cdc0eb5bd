#pragma once
// Assembly of the per-axis stiffness K^d = L_w + diag(k^d) (vdm-model.md section 3) into the
// fixed pattern, and per-axis elimination of constrained entries (Dirichlet rows/columns).
#include <array>
#include <vector>

#include "engine/geometry.hpp"
#include "engine/sparse.hpp"
#include "engine/tissue_model.hpp"

namespace vdm {

// Writes K^d for d = x, y, z at the geometry (A_i, V_i) into K (sized: E weights, N x 3
// diagonals). `area_norms` (N): |A_i|; `volume_scale`: how the V_i were made from them
// (distributed_volumes_from_norms; the default VolumeScale for V_i of any other form);
// `extra_diagonal` (N, may be empty) is added to every axis: the inertia term M/h^2 + D/h;
// `scratch` (N) to work in. No allocation.
//   bulk:          k_i^d = B_i^d (A_i^d)^2 / V_i                          eq (3)
//   connectivity:  w_ij  = B_ij a_ij^2 / V_ij, a_ij = (|A_i|+|A_j|)/2, V_ij = (V_i+V_j)/2   eq (4)
// With V_i = scale |A_i| at both ends, V_ij = scale a_ij and w_ij = (B_ij / (2 scale))
// (|A_i| + |A_j|): no division (the formula above where an end is floored).
void assemble_stiffness(const TissueModel& model, const NodeMat& area_vectors, const Vec& area_norms,
                        const Vec& node_volumes, const VolumeScale& volume_scale, const Vec& extra_diagonal,
                        AxisStiffness& K, Vec& scratch);
// The same into per-axis sparse matrices on `model.pattern` for V_i of any form (values
// only; allocates).
void assemble_stiffness(const TissueModel& model, const NodeMat& area_vectors,
                        const Vec& node_volumes, const Vec& extra_diagonal,
                        std::array<SpMat, 3>& K);
// K^d as sparse matrices on `pattern` (values written; the matrices carry the pattern).
void to_sparse(const StiffnessPattern& pattern, const AxisStiffness& K, std::array<SpMat, 3>& out);

// Y = K X: column d of Y is K^d times column d of X. The three axes share the edge weights,
// so one pass over the edges serves them all (each axis summed in the order of a pass of its
// own).
void multiply(const StiffnessPattern& pattern, const AxisStiffness& K, const NodeMat& X, NodeMat& Y);

// Right-hand side of the eliminated system (per axis its mask, load, prescribed values):
// rhs_i = f_i - sum_{j constrained} K_ij u_j for free i, rhs_j = u_j for constrained j. Only
// the edge weights enter, the same on every axis; only the constrained entries with a value
// (not the held ones, u_j = 0) move anything, along their nodes' edges (the model's
// `neighbours`). `f` null: no loads (f = 0, the same bits as a zero array). The step uses the
// listed variant below; this one, from the flags alone, is its reference in the tests.
void eliminate_rhs(const NeighbourLists& neighbours, const AxisStiffness& K, const FlagMat& mask,
                   const NodeMat* f, const NodeMat& u_fixed, NodeMat& rhs);
// The same, bit for bit, with the constrained entries (the set ones of `mask`) listed as
// indices d N + i into the N x 3 arrays, each once, ascending within each list: the held
// ones (u_fixed zero there) and the prescribed ones (the step's lists, StepWorkspace). No
// pass over the flags: the loads are copied whole and the few listed entries set after.
// Without loads, rhs is zero but at the prescribed entries and their neighbours on their
// axes (the held entries' zero included); `zero_elsewhere` says that rhs is so already (a
// call without loads and with these entries, or with entries since cleared by
// clear_prescribed_support()): then only those entries are written again, not the whole
// array (at 40k nodes the 1 MB of zeros written every step was about 4 % of it).
void eliminate_rhs(const NeighbourLists& neighbours, const AxisStiffness& K, const FlagMat& mask,
                   const std::vector<int>& held_entries, const std::vector<int>& prescribed_entries, const NodeMat* f,
                   const NodeMat& u_fixed, NodeMat& rhs, bool zero_elsewhere = false);
// Zero at the listed prescribed entries and their neighbours on their axes: what a call of
// eliminate_rhs() without loads may have set.
void clear_prescribed_support(const NeighbourLists& neighbours, const std::vector<int>& prescribed_entries,
                              NodeMat& rhs);

// K_masked = K with rows and columns of constrained nodes (mask(i) != 0) replaced by the
// identity. Same pattern, values written in place.
void mask_constrained(const SpMat& K, const std::uint8_t* mask, SpMat& K_masked);

// y = K x for the symmetric K.
void symmetric_multiply(const SpMat& K, const double* x, double* y);

}  // namespace vdm
