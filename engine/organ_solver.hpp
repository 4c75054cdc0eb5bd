#pragma once
// One interface for the three organ models a scene or an experiment can pick
// (`organ.model: vdm | fem | mass_spring`). Each reads the same StepInput on the organ's
// surface nodes and writes the same SimState fields: u, x, velocity, volume,
// volume_rel_error, pressure, reaction (on constrained surface entries), stats (iterations,
// residual, converged, step_ms, solve_ms) and warnings. The SimState comes from
// make_sim_state() on a TissueModel of the same surface. VDM-only fields (area vectors,
// node volumes, strain, stress, reaction_pressure) stay as they are for fem and mass_spring.
#include <memory>

#include "engine/fem/fem_model.hpp"
#include "engine/mass_spring.hpp"
#include "engine/sim_state.hpp"

namespace vdm {

enum class ModelKind { vdm, fem, mass_spring };
const char* to_string(ModelKind k);
bool parse_model_kind(const std::string& text, ModelKind& out);

class OrganSolver {
 public:
  virtual ~OrganSolver() = default;
  virtual ModelKind kind() const = 0;
  // One quasi-static step; `state` is a SimState of this organ's surface.
  virtual void step(const StepInput& input, SimState& state) = 0;
};

// The VDM engine (vdm::step on `model`, which must outlive the solver).
std::unique_ptr<OrganSolver> make_vdm_solver(const TissueModel& model);
// The FEM reference; `dt` only advances state.time.
std::unique_ptr<OrganSolver> make_fem_solver(fem::FemModel model, double dt);
// Surface springs (+ optional volume spring).
std::unique_ptr<OrganSolver> make_mass_spring_solver(MassSpringModel model, double dt);

}  // namespace vdm
