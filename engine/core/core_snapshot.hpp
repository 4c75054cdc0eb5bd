#pragma once
// Binary snapshots of the elastic core's state (CoreState), for resuming a run bit for bit
// (app/run/checkpoint.hpp): what a step reads of the steps before it.
//  - The surface's and the lattice's displacements and velocities, where the step in progress
//    started, the last static step's motion (the next step's first guess), the results, and
//    the warnings so far (a full list takes no more).
//  - Each tet's last rotation as a quaternion: the next fit starts from it, and where the fit
//    stops depends on where it starts.
//  - The factors kept across steps: which prescribed entries each of the three factor slots
//    was made for, which axis uses which, and the columns of K^-1 solved through them (their
//    lattice nodes, in the groups they were solved in). The matrices are built again from
//    the masks and factorised, and the columns solved again in the same groups: the same
//    inputs give the same bits.
//  - The held entries (prescribed entries the factor does not hold) and their compliance
//    matrix C0 as it is, factorised again on load (a factor kept while the set is the same).
// The step's scratch (the Anderson history, the linear system's loads and responses, the
// held entries' multipliers) is rewritten by every step before it is read, and is not saved.
#include <string>
#include <string_view>

#include "engine/core/elastic_core.hpp"

namespace vdm::core {

// Appends the snapshot of `state` (of `model`) to `out`.
void save_core_state(const CoreModel& model, const CoreState& state, std::string& out);

// Reads a snapshot from `in` at `pos` (moved past it) into `state`, which make_core_state(model)
// made, and rebuilds its factors. False with the reason when the bytes are not a snapshot of a
// state of this model (truncated, damaged, of another lattice), or a factor does not factorise.
bool load_core_state(const CoreModel& model, std::string_view in, size_t& pos, CoreState& state, std::string& error);

// What a state carries between steps besides its arrays, in numbers (tests and diagnostics:
// the workspace is internal to engine/core): the held entries and whether their compliance is
// factorised, the factor slots made, the entries the factors hold, and the columns of K^-1
// kept through them with the solves that made them.
struct CoreCarry {
  int held = 0;
  bool held_factored = false;
  int factors = 0;
  FlagMat factored;  // ns x 3: the prescribed entries the factors hold
  int columns = 0, column_solves = 0;
};
CoreCarry core_carry(const CoreState& state);

}  // namespace vdm::core
