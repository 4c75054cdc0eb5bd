#pragma once
// Resuming an interrupted run. The checkpoint (DIR/checkpoint.json, rewritten every K frames
// once their images are on disk, and when the run stops) records the last complete frame, a
// hash of the scene and options, and a hash of the simulation state after that frame. On
// --resume the state is rebuilt by re-simulating up to that frame without rendering (the
// simulation is deterministic; far cheaper than the pictures) and checked against the hash
// before the run goes on, so the result is identical to an uninterrupted run.
#include <string>

#include "engine/sim_state.hpp"

namespace vdmsim {

struct Checkpoint {
  std::string run_hash;    // scene file content + the options that change results
  int frame = -1;          // last complete frame (metrics row and images written)
  int frames = 0;          // frames requested
  std::string state_hash;  // of the state after `frame`
  double range_lo = 0, range_hi = 0;  // the stress view's automatic colour range (lo < hi when set)
};

// A 64-bit FNV-1a-style hash of the displacement, velocity, pressure, step and time (hex).
std::string state_hash(const vdm::SimState& state);
// Hash of a file's bytes plus `extra` (hex); empty if the file cannot be read.
std::string run_hash(const std::string& scene_file, const std::string& extra);

bool write_checkpoint(const std::string& path, const Checkpoint& cp, std::string& error);
bool read_checkpoint(const std::string& path, Checkpoint& cp, std::string& error);

}  // namespace vdmsim
