#pragma once
// One interface for the organ models a scene or an experiment can pick
// (`organ.model: vdm | vdm_core | fem | mass_spring`). Each reads the same StepInput on the organ's
// surface nodes and writes the same SimState fields: u, x, velocity, volume,
// volume_rel_error, pressure, reaction (on constrained surface entries), stats (iterations,
// residual, converged, step_ms, solve_ms) and warnings. The SimState comes from
// make_sim_state() on a TissueModel of the same surface. vdm and vdm_core also write the area
// vectors, reaction_pressure and (when their model computes stress) strain and stress; those
// and the node volumes stay as they are for fem and mass_spring.
//
// Contact (engine/contact.hpp) solves a step several times under other contact loads or
// constraints: it takes the step with trial_step(), goes back to the step's start with
// rewind(), reads where the step started with start_u(), and completes the step it keeps
// with finish_step(). Every model does these, so every contact method runs on every model
// that takes its loads (penalty contact needs takes_springs()).
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/fem/fem_model.hpp"
#include "engine/mass_spring.hpp"
#include "engine/sim_state.hpp"
#include "engine/sparse.hpp"

namespace vdm {

namespace core {
struct CoreModel;
}
class SurfaceForceLaw;

enum class ModelKind { vdm, fem, mass_spring, vdm_core };
const char* to_string(ModelKind k);
bool parse_model_kind(const std::string& text, ModelKind& out);

class OrganSolver {
 public:
  virtual ~OrganSolver() = default;
  virtual ModelKind kind() const = 0;
  // One quasi-static step; `state` is a SimState of this organ's surface.
  virtual void step(const StepInput& input, SimState& state) = 0;

  // A step that may be solved again: `results` as vdm::step's (what it may leave to
  // finish_step()). The reference models compute every result whatever it says.
  virtual void trial_step(const StepInput& input, SimState& state, StepResults results) = 0;
  // The results the last trial_step() left out (vdm: finish_step_results()).
  virtual void finish_step(SimState& state) = 0;
  // Whether the steps from now on compute the surface's strain and stress, where the model
  // computes them at all (vdm_core with the stress effect): a scene turns it off for a frame's
  // sub-steps before its last, whose stress nothing reads.
  virtual void set_surface_stress(bool on) { (void)on; }
  // Puts `state` back at the start of its last step (u, x, velocity, step count and time;
  // vdm: also the engine's geometry and matrices, rewind_step()), to solve that step again.
  // The static reference models' next solve starts from their last solution, and reaches the
  // same equilibrium in fewer iterations; vdm_core with inertia starts again where the step
  // started (its lattice's position and velocity).
  virtual void rewind(SimState& state) = 0;
  // The displacements (N x 3) where the state's last step started (after it, or after
  // rewind()); before any step, the state's own.
  virtual const NodeMat& start_u(const SimState& state) const = 0;
  // Whether a step takes StepInput::spring_k and spring_u (penalty contact needs them).
  virtual bool takes_springs() const = 0;
  // Whether a step's solves stop at StepInput::tolerance when it is given (constraint
  // contact's loose solves); otherwise they solve to their own tolerance every time.
  virtual bool takes_tolerance() const = 0;
  // A per-axis stiffness of the surface (K^d on `surface`'s edges) from which constraint
  // contact computes its compliance model, and a number that changes when it does. vdm: the
  // engine's own K at its last refresh. The reference models: VDM's K of `surface` at rest
  // (with its moduli): a model of their response that contact scales to the solves it sees.
  virtual const AxisStiffness& contact_stiffness(const TissueModel& surface, const SimState& state) = 0;
  virtual long contact_stiffness_version(const SimState& state) const = 0;
  // The organ's exact compliance at surface nodes `nodes` (3n x 3n; row 3a + d, column 3b + e:
  // how far node a moves along d under a unit force on node b along e) at its last solve, with
  // what that solve prescribed held. False when the model cannot give it cheaply: contact then
  // models it from contact_stiffness(). vdm_core: through its lattice's factor.
  virtual bool surface_compliance(const std::vector<int>& nodes, Eigen::MatrixXd& C) {
    (void)nodes;
    (void)C;
    return false;
  }
  // Whether the model has trial_step_with(): a trial_step() whose surface forces `law` sets
  // inside the model's own nonlinear iteration, after each of its linear solves
  // (engine/surface_force_law.hpp). Without it (false, doing nothing), constraint contact
  // iterates whole solves. vdm_core: yes.
  virtual bool solves_force_laws() const { return false; }
  virtual bool trial_step_with(const StepInput& input, SimState& state, SurfaceForceLaw& law) {
    (void)input;
    (void)state;
    (void)law;
    return false;
  }
  // A trial_step_with() whose iteration the caller drives, so that several organs' steps are
  // iterated together (contact between organs, engine/organ_pair_contact.hpp): joint_begin()
  // (false: the model cannot, or the step failed at its start, reported in the state); then per
  // iteration joint_solve() (one linear solve, with `law`'s forces) and joint_converged()
  // (whether that solve reached the iteration's fixed point), where joint_forces() may then be
  // changed and joint_forces_changed() moves the iteration's answer (joint_surface()) by their
  // change (the next iterate mixed from it); joint_advance(stop) (false: the iteration is
  // over); joint_end(). vdm_core: the core's step in its parts (engine/core/elastic_core.hpp).
  virtual bool joint_begin(const StepInput& input, SimState& state, SurfaceForceLaw* law) {
    (void)input;
    (void)state;
    (void)law;
    return false;
  }
  virtual void joint_solve() {}
  virtual const NodeMat& joint_surface() const { return empty_; }
  virtual NodeMat& joint_forces() { return empty_; }
  virtual void joint_forces_changed() {}
  virtual bool joint_converged() { return true; }
  virtual bool joint_advance(bool stop) {
    (void)stop;
    return false;
  }
  virtual void joint_end(SimState& state) { (void)state; }
  // The motion below which the iteration counts as converged (m).
  virtual double joint_tolerance() const { return 0; }
  // A snapshot of what the model carries from one step to the next, between steps, appended to
  // `out`: with the SimState's own snapshot (engine/state_snapshot.hpp) a solver loaded from it
  // continues bit for bit. False, appending nothing, when the model does not save its state
  // (fem, mass_spring: a resumed run re-simulates). vdm: nothing to add (the engine's state is
  // the SimState's). vdm_core: engine/core/core_snapshot.hpp.
  virtual bool save_state(std::string& out) const {
    (void)out;
    return false;
  }
  // Reads a snapshot save_state() wrote for the same model from `in` at `pos` (moved past it).
  // False with the reason when it is not one.
  virtual bool load_state(std::string_view in, size_t& pos, std::string& error) {
    (void)in;
    (void)pos;
    error = "state snapshot: a reference model's state is not saved";
    return false;
  }
 private:
  NodeMat empty_;
};

// The VDM engine (vdm::step on `model`, which must outlive the solver).
std::unique_ptr<OrganSolver> make_vdm_solver(const TissueModel& model);
// The FEM reference; `dt` only advances state.time.
std::unique_ptr<OrganSolver> make_fem_solver(fem::FemModel model, double dt);
// VDM's surface and pressure on an elastic core (engine/core).
std::unique_ptr<OrganSolver> make_core_solver(core::CoreModel model, double dt);
// Surface springs (+ optional volume spring).
std::unique_ptr<OrganSolver> make_mass_spring_solver(MassSpringModel model, double dt);

}  // namespace vdm
