#pragma once
// Binary snapshots of a SimState, for resuming a run bit for bit (app/checkpoint): the state's
// arrays and counters, and what the engine carries from one step to the next: the geometry of
// the last refresh and its refresh counter, the constrained set and springs of the solver's
// matrices, the linear solver's warm starts and cached pressure response, and the last loads
// (halved steps).
// Matrices and factorisations are rebuilt from those, as the run built them, so the steps
// after a load give the same bits as the steps of the run that saved it.
#include <string>
#include <string_view>

#include "engine/sim_state.hpp"

namespace vdm {

// Appends the snapshot of `state` (of `model`) to `out`.
void save_state(const TissueModel& model, const SimState& state, std::string& out);

// Reads a snapshot from `in` at `pos` (moved past it) into `state`, which make_sim_state(model)
// made. False with the reason when the bytes are not a snapshot of a state of this model.
bool load_state(const TissueModel& model, std::string_view in, size_t& pos, SimState& state, std::string& error);

}  // namespace vdm
