#pragma once
// The results of a step after its nonlinear iterations, in one gather over the nodes'
// neighbour lists: K u, the reactions at constrained entries and the residual of the free
// ones, the contact pressure, strain and stress (vdm-model.md sections 3, 5, 7).
#include <cstddef>
#include <vector>

#include "engine/sim_state.hpp"

namespace vdm {

// What the pass reads besides the model and the state (the step's workspace).
struct StepResultsInput {
  const AxisStiffness& K;  // K^d = L_w + diag(k^d) of the last solve (unmasked)
  const FlagMat& mask;     // constrained entries
  const NodeMat* force;    // the step's loads f; null: none (f = 0)
  const NodeMat* springs;  // spring constants k on the free rows' diagonal; null: none
  const Vec& area_norms;   // |A_i| of s.area_vectors
  const NodeMat& rhs;      // the eliminated right-hand side (for its norm)
};

// Doubles of compute_step_results()'s scratch for `n` nodes.
inline size_t result_rows_size(int n) { return 6 * size_t(n); }

// The nodes whose packed values the pass keeps in that scratch at a time: fewer than `n` (a
// ring, in the core's caches) when every node's neighbours are within `reach` of it in node
// order and the ring is small (the generated livers), else n.
std::ptrdiff_t result_ring_nodes(int reach, std::ptrdiff_t n);

// Per-axis sums for the step's relative residual (each the even nodes' sum plus the odd
// nodes': the pass takes two nodes at a time).
struct ResidualSums {
  double free2[3] = {0, 0, 0};       // free entries' ((K^d + diag k^d) u - dP A - f)_i^2
  double rhs2[3] = {0, 0, 0};        // rhs_i^2
  double volume_row[3] = {0, 0, 0};  // A_i u_i on the free entries (the volume row)
};

// Writes s.reaction ((K u)_i - dP A_i - f_i on constrained entries, 0 on free ones: the
// constrained rows' residual is zero, u being pinned to its values), s.reaction_pressure
// (|reaction_i| / |A_i| on nodes with a constrained entry, else 0) and, when
// model.compute_stress, s.strain and s.stress: those of compute_strain_stress() to
// round-off (the neighbour sums are taken in another order). `rows`: scratch of
// result_rows_size(N) doubles (the step lends the solver's: LinearSolver::spare_doubles).
// One pass to pack u and A o u in planes of pairs, one gather.
ResidualSums compute_step_results(const TissueModel& model, const StepResultsInput& in, SimState& s, double* rows);

}  // namespace vdm
