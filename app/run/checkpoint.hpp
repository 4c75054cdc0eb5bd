#pragma once
// Resuming an interrupted run. The checkpoint (DIR/checkpoint.json, rewritten every K frames
// once their images are on disk, and when the run stops) records the last complete frame, a
// hash of the scene and options, and a hash of the simulation state after that frame. On
// --resume the state is loaded from the state snapshot taken with the checkpoint (state.bin),
// or, without one (a reference model, an older run), rebuilt by re-simulating up to that frame
// without rendering (the simulation is deterministic); either way it is checked against the
// hash before the run goes on, so the result is identical to an uninterrupted run.
#include <string>
#include <utility>
#include <vector>

#include "engine/sim_state.hpp"

namespace vdmsim {

// Everything a run's result depends on, each with the hash of its content: the scene file, every
// file it loads (the organ mesh, instrument meshes and skins), the options that change results,
// and the program itself. A resume with any of them changed is refused, naming what changed.
struct RunInputs {
  // (what, hash of its content, or the value itself in words); neither has ';' or '='.
  std::vector<std::pair<std::string, std::string>> items;
  std::string hash() const;                                // of them all (the run hash)
  std::string text() const;                                // "what=hash;..." (checkpoint.json)
  static RunInputs parse(const std::string& text);
  // What differs from `earlier` (changed, added or gone), in words; empty when nothing.
  std::vector<std::string> changes_since(const RunInputs& earlier) const;
};
// Hash of a file's bytes (hex); empty when it cannot be read.
std::string file_hash(const std::string& path);

struct Checkpoint {
  std::string run_hash;    // RunInputs::hash() of the run
  std::string inputs;      // RunInputs::text() of the run
  int frame = -1;          // last complete frame (metrics row and images written)
  int frames = 0;          // frames requested
  std::string state_hash;  // of the state after `frame`
  double range_lo = 0, range_hi = 0;  // the stress view's automatic colour range (lo < hi when set)
};

// A 64-bit FNV-1a-style hash of the displacement, velocity, pressure, step and time (hex).
std::string state_hash(const vdm::SimState& state);

bool write_checkpoint(const std::string& path, const Checkpoint& cp, std::string& error);
bool read_checkpoint(const std::string& path, Checkpoint& cp, std::string& error);

// The state snapshot next to the checkpoint (DIR/state.bin): the run hash, the frame after
// which it was taken, the run's largest volume error so far, and the simulation's snapshot
// (SceneSimulation::save), with a checksum of all of it. A resume that finds one of the
// checkpoint's frame and run loads it instead of re-simulating; written to a temporary file
// and renamed into place. read_state_file() sets `damaged` when the file is there but its
// checksum or layout is wrong.
struct StateFile {
  std::string run_hash;
  int frame = -1;
  double max_volume_error = 0;
  std::string snapshot;
};
bool write_state_file(const std::string& path, const StateFile& sf, std::string& error);
bool read_state_file(const std::string& path, StateFile& sf, std::string& error, bool* damaged = nullptr);

}  // namespace vdmsim
