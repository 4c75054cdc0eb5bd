#pragma once
// SimState: everything that changes during a run (MuJoCo's mjData). Arrays are sized once by
// make_sim_state(); step() writes them in place. StepInput: the loads and constraints of one
// step, filled by the caller (scripted loads, contact, grasp).
#include <memory>
#include <string>
#include <vector>

#include "engine/tissue_model.hpp"

namespace vdm {

struct StepInput {
  NodeMat force;         // N x 3 external node forces (N): contact penalty, user loads
  Vec pressure;          // N external pressure on each node's patch (Pa, > 0 pushes inward);
                         // size 0 = none. Adds -pressure_i A_i to the force.
  FlagMat prescribed;    // N x 3: 1 = u_i^d prescribed this step (contact, grasp, motion)
  NodeMat prescribed_u;  // N x 3 total displacement from rest for prescribed entries (m)
  // Springs per node and axis (penalty contact): the force spring_k (spring_u - u) on every
  // free entry, solved implicitly (spring_k joins the diagonal of K^d). N x 3, N/m, >= 0;
  // 0 rows = none. spring_u: the springs' rest displacements from the rest shape (m).
  NodeMat spring_k;
  NodeMat spring_u;
  // The linear solves' relative residual for this step; 0: the model's solver.tolerance. A
  // caller that will solve the step again (constraint contact's iterations) may loosen it
  // for the solves it does not keep. Only a tighter tolerance than the model's has no use.
  double tolerance = 0;
  void clear();          // zero everything, keep sizes
};

StepInput make_step_input(const TissueModel& model);

struct StepStats {
  int iterations = 0;            // Krylov iterations this step (sum over all solves)
  double residual = 0;           // relative residual of the full 3N+1 system after the step
  bool converged = true;         // every linear solve reached its tolerance (after fallbacks)
  int nonlinear_iterations = 0;  // solves this step
  double nonlinear_change = 0;   // last max |u_solved - u| / model size of the nonlinear iteration
  double relaxation = 1;         // last relaxation factor of the nonlinear iteration (Aitken)
  int fallbacks = 0;             // solves redone another way this step (see `fallback`)
  const char* fallback = nullptr;  // why the last fallback happened (static text), or null
  bool refreshed = false;        // geometry and matrix recomputed this step
  int factorizations = 0;        // matrix (re)factorisations / preconditioner setups this step
  double step_ms = 0, assemble_ms = 0, solve_ms = 0, stress_ms = 0;
  long total_refreshes = 0, total_factorizations = 0, total_fallbacks = 0;
};

struct StepWorkspace;  // solver matrices and scratch (engine-internal)

struct SimState {
  long step = 0;           // completed steps
  double time = 0;         // s
  NodeMat u;               // N x 3 displacement from rest, the paper's Delta L (m)
  NodeMat x;               // N x 3 current positions X + u (m)
  NodeMat velocity;        // N x 3 (m/s), (u^{n+1} - u^n) / dt
  NodeMat area_vectors;    // N x 3 A_i at the geometry of the last refresh (m^2), eq (1)
  Vec node_volumes;        // N V_i at the last refresh (m^3), eq (2)
  double volume = 0;       // current enclosed volume (m^3)
  double volume_rel_error = 0;  // (V - V_0) / V_0
  double pressure = 0;     // uniform fluid pressure change Delta P (Pa), eq (10)
  NodeMat reaction;        // N x 3 force the constraints apply to the organ, K u - dP A - f (N);
                           // zero where free. The organ pushes an instrument with -reaction.
  Vec reaction_pressure;   // N |reaction_i| / |A_i| (Pa): the contact pressure C_i
  NodeMat strain;          // N x 3 per-axis volumetric strain dV_i^d / V_i, eq (5)
  NodeMat stress;          // N x 3 per-axis stress (Pa), eq (6)
  StepStats stats;
  std::vector<std::string> warnings;  // numerical trouble met so far (kept short)
  // The last step could not be done at all (bad input, or every solver failed): the state
  // was left as it was before that step (step and time not advanced) and `failure` says why.
  // The caller should stop. Cleared by the next step.
  bool failed = false;
  std::string failure;
  std::unique_ptr<StepWorkspace> work;

  SimState();
  ~SimState();
  SimState(SimState&&) noexcept;
  SimState& operator=(SimState&&) noexcept;
};

// State at rest for `model`, with the solver chosen in model.solver set up.
SimState make_sim_state(const TissueModel& model);

// One quasi-static (or, with inertia, implicit Euler) step (vdm-model.md section 4).
// When an iterative solve does not converge (or gives a non-finite result) the solve is
// redone with the direct solver (stats.fallbacks, stats.fallback). A step that still cannot
// be done (no solver can solve it, the surface turns inside out, the result is not finite or
// the volume drifts past 1e-4) is redone as two halves of its load increment (forces and
// pressures interpolated from the last step's input, prescribed displacements from where
// the nodes are), each half split again if need be, down to 1/8; it counts as one step
// (stats.fallbacks, stats.fallback and a warning say so). Quasi-static models only. When
// that fails too, or the input is malformed, the step fails (state.failed, state.failure)
// and changes nothing.
//
// `results`: what the step computes after its solve. A caller that may redo the step with
// other constraints (the contact's active set, the penalty contact's iterations) can leave
// the results pass out of the steps it will not keep, and then call finish_step_results()
// for the one it keeps: the state is then the same, bit for bit, as with StepResults::all.
enum class StepResults {
  all,        // s.reaction, s.reaction_pressure, s.strain, s.stress and stats.residual
  reactions,  // s.reaction at the entries the input prescribes only (the same values as
              // `all` gives there); the rest is left as it was until finish_step_results()
  none,       // none of them until finish_step_results()
};
void step(const TissueModel& model, const StepInput& input, SimState& state, StepResults results = StepResults::all);

// Computes the results a step() with StepResults::reactions or none left out (those of the
// state's last step). Does nothing when there are none pending: after a step with
// StepResults::all, or after rewind_step() or a failed step (the state is the step's start).
void finish_step_results(const TissueModel& model, SimState& state);

// Puts the state back as it was before the last step() call: displacement, velocity,
// pressure, step count and time, and the engine's geometry, matrices and refresh counter,
// so that the same step can be solved again with other constraints (contact's active set).
void rewind_step(const TissueModel& model, SimState& state);

}  // namespace vdm
