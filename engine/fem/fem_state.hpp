#pragma once
// Per-run state of the FEM reference and its static step (Newton on the corotational energy
// of fem_model.hpp, with a backtracking line search on the energy; a step that fails to
// converge or would invert a tet is split in two and retried).
#include <memory>
#include <string>
#include <vector>

#include "engine/fem/fem_model.hpp"
#include "engine/sim_state.hpp"

namespace vdm::fem {

struct FemStats {
  int iterations = 0;      // Newton iterations this step (all substeps)
  int substeps = 0;        // increments the step was solved in (1 = no splitting)
  double residual = 0;     // free residual / force scale at the end
  bool converged = true;
  double step_ms = 0;
};

struct FemWorkspace;

struct FemState {
  NodeMat u;               // n x 3 displacement from rest (m), interior nodes included
  NodeMat reaction;        // n x 3 force the constraints apply to the body (N), zero where free
  NodeMat applied;         // n x 3 external force in equilibrium with the current u (N)
  double volume = 0;       // current volume, sum_e V_e det F_e (m^3)
  double volume_rel_error = 0;
  double pressure = 0;     // volume-averaged pressure -lambda theta (Pa)
  FemStats stats;
  std::vector<std::string> warnings;
  std::unique_ptr<FemWorkspace> work;
  FemState();
  ~FemState();
  FemState(FemState&&) noexcept;
  FemState& operator=(FemState&&) noexcept;
};

FemState make_fem_state(const FemModel& model);

// One static step: loads and constraints of `input` act on the surface nodes (its arrays
// have model.ns rows; `pressure`, when given, pushes each surface node's patch inward).
void step(const FemModel& model, const StepInput& input, FemState& state);

// The total energy at displacement u under external force f (J), +inf if a tet is inverted;
// with `gradient`, also dE/du (n x 3). For tests and calibration.
double energy(const FemModel& model, const NodeMat& u, const NodeMat& f, NodeMat* gradient);

}  // namespace vdm::fem
