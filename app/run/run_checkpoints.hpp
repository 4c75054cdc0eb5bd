#pragma once
// A run's resume points: DIR/checkpoint.json every K frames and when the run stops, each with
// the state snapshot (DIR/state.bin) written first. A resume loads the snapshot when it is of
// the checkpoint's frame and re-simulates otherwise; the snapshot only saves time, so when it
// cannot be written (disk full) the run goes on without it.
#include <ostream>
#include <string>

#include "app/run/frame_output.hpp"
#include "app/run/run_setup.hpp"
#include "app/simulation/scene_simulation.hpp"

namespace vdmsim {

enum class SnapshotLoad { loaded, absent, damaged };

class RunCheckpoints {
 public:
  RunCheckpoints(const PreparedScene& prepared, const RunSetup& setup, const FrameOutput& output, std::ostream& err);
  // Resuming: loads the snapshot taken with the checkpoint into `sim` when it reproduces the
  // checkpoint's state (checked on a scratch simulation first, so that one that does not load
  // leaves `sim` as new). True when loaded, with the run's largest volume error so far.
  // Loads DIR/state.bin into `sim` when it holds the checkpoint's frame of this run. Absent (or
  // of another frame): the run re-simulates; damaged (checksum, layout, or a state that is not
  // the checkpoint's): `error` says why and the resume is refused.
  SnapshotLoad load_snapshot(SceneSimulation& sim, double& max_volume_error, std::string& error) const;
  // The checkpoint after `frame`, whose state has hash `state_hash`, with its snapshot of
  // `sim`. False with `error` when the checkpoint could not be written.
  bool write(int frame, const std::string& state_hash, const SceneSimulation& sim, double max_volume_error,
             std::string& error);
  // The last checkpoint, after the last complete frame: with a snapshot of `sim` when it is
  // given (its state is that frame's), without one (state.bin removed) otherwise. A failure
  // is a warning: the run's outputs are complete.
  void write_last(int frame, const std::string& state_hash, const SceneSimulation* sim, double max_volume_error);

 private:
  Checkpoint at(int frame, const std::string& state_hash) const;
  void save_snapshot(int frame, const SceneSimulation& sim, double max_volume_error);

  const PreparedScene& ps_;
  const RunSetup& setup_;
  const FrameOutput& output_;
  std::ostream& err_;
  bool snapshots_ = true;  // false once a snapshot could not be written
};

}  // namespace vdmsim
