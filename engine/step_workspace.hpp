#pragma once
// Engine-internal per-run scratch owned by SimState: matrices, constraint masks, loads and the
// chosen linear solver. Sized once in make_sim_state(); step() allocates nothing after that,
// except once: the first step done in parts makes the arrays of halved steps (sub_input, whole_*),
// and the first step with springs, a force or a pressure sizes the array that keeps it.
#include <array>
#include <memory>
#include <vector>

#include "engine/linear_solver.hpp"
#include "engine/sim_state.hpp"

namespace vdm {

// Where a step started: what rewind_step() brings back.
struct StepStart {
  NodeMat u, velocity;
  NodeMat x_refresh;  // positions of the geometry then (kept, and sized, when refresh_every > 1 and nonlinear_iterations > 1)
  double pressure = 0, time = 0;
  long step = 0;
  int since_refresh = 0;  // steps_since_refresh then
  bool have_geometry = false;
};

struct StepWorkspace {
  AxisStiffness K;                // per-axis K^d at the last refresh (unmasked)
  FlagMat mask, last_mask;        // constrained entries this step / when the solver was last told
  // The constrained entries as indices d N + i into the N x 3 arrays: the model's held ones
  // (m.held: every step, value 0) and this step's prescribed ones that are not held (few: the
  // contact's; build_constraints, capacity 3 N).
  std::vector<int> held_entries, prescribed_entries;
  NodeMat last_springs;           // StepInput::spring_k when the solver was last told (N x 3; 0 rows, all
                                  // zero, until the first step with springs: most runs have none)
  bool last_springs_any = false;  // some of last_springs is not zero
  double mean_diagonal = 1.0;     // of the eliminated matrices (the residual's pressure scale)
  NodeMat u_fixed;                // values of constrained entries (m), zero on the others
  NodeMat a_free;                 // area vectors, zero on constrained entries
  NodeMat force;                  // total load f this step (N)
  std::vector<double> rotations;  // the corotational capsule's node rotations (NodeRotations; 9 N, else empty)
  NodeMat rhs;                    // eliminated right-hand side
  bool rhs_zero_elsewhere = false;  // rhs is zero but at prescribed_entries and their neighbours (eliminate_rhs())
  NodeMat u_new;                  // solver output
  NodeMat x_refresh;              // positions at the last refresh: the geometry of K, A, V_i, loads
  NodeMat residual_prev;          // previous fixed-point residual (Aitken relaxation; nonlinear_iterations > 1 only)
  StepStart start;                // the start of the current step, for rewind_step()
  bool refreshed_in_step = false;
  bool rewound = false;           // rewind_step() since the last step (the next may find its geometry current)
  bool volume_met = false;        // the last solve met the volume tolerance without a correction
  bool u_verified_finite = false; // the step's first solve found every entry of the u it wrote finite, and
                                  // nothing moved u since (else trouble_with() checks u itself)
  // The last step's results pass, when its caller deferred it (StepResults::reactions or
  // none): what finish_step_results() needs besides K, mask, force, rhs and a_free.
  bool results_pending = false;
  bool results_loads = false;     // w.force holds that step's loads
  double results_volume_rhs = 0;  // its volume row's right-hand side (c plus the corrections' shift)
  double volume_at_refresh = 0;   // enclosed volume at x_refresh
  // Halved load increments (step() in step.cpp): the loads of the last two completed steps,
  // the input of a part of a step, and the whole step's start while it is done in parts.
  // A load that is zero is not copied: its *_zero flag says so, and its array (sized by the
  // first step with such a load) is not read. Runs without forces or pressures have none.
  NodeMat force_last, force_prev;
  Vec pressure_last, pressure_prev;
  bool force_last_zero = true, force_prev_zero = true, pressure_last_zero = true, pressure_prev_zero = true;
  bool input_remembered = false;  // force_last/pressure_last are the current step's (rewind swaps back)
  StepInput sub_input;
  StepStart whole;                // the whole step's start (x_refresh: the geometry's positions then)
  const char* failure_reason = nullptr;  // why the last attempt failed (static text)
  Vec extra_diagonal;             // inertia M/h^2 + D/h (empty without inertia)
  Vec scratch;                    // N
  Vec area_norms;                 // |A_i| at the last refresh (N)
  std::vector<double> result_rows;  // compute_step_results()'s node rows when the solver lends none
  std::vector<double> packed;     // 6 N: packed_area_sums_and_volume()'s and volume_along()'s rows
  // packed holds positions and their area sums (packed_area_sums_and_volume) enclosing
  // packed_volume: the step's last volume check leaves them for the next refresh.
  bool packed_valid = false;
  double packed_volume = 0;
  std::unique_ptr<LinearSolver> solver;
  std::unique_ptr<LinearSolver> fallback;  // direct solver, made on the first failed solve
  bool fallback_stale = true;              // fallback not told of the current system
  bool matrix_dirty = true;       // K changed since the solver was last told
  bool have_geometry = false;     // a refresh has happened
  int steps_since_refresh = 0;
};

// Rebuilds what a step leaves behind from the workspace's saved parts (engine/state_snapshot):
// K^d, A_i, V_i at x_refresh, and the system for last_mask given to the solver, as the last
// step built them (the refresh counter is kept).
void rebuild_matrices(const TissueModel& model, SimState& state);

}  // namespace vdm
