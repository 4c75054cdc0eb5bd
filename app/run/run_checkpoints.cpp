#include "app/run/run_checkpoints.hpp"

#include <filesystem>

namespace vdmsim {

namespace fs = std::filesystem;

RunCheckpoints::RunCheckpoints(const PreparedScene& ps, const RunSetup& setup, const FrameOutput& output,
                               std::ostream& err)
    : ps_(ps), setup_(setup), output_(output), err_(err) {}

SnapshotLoad RunCheckpoints::load_snapshot(SceneSimulation& sim, double& max_volume_error, std::string& error) const {
  const Checkpoint& cp = setup_.resume_from;
  StateFile sf;
  std::string why;
  bool damaged = false;
  if (!read_state_file((setup_.dir / "state.bin").string(), sf, why, &damaged)) {
    if (damaged) error = why;
    return damaged ? SnapshotLoad::damaged : SnapshotLoad::absent;
  }
  // A snapshot of another frame (the run stopped between a checkpoint and the next snapshot)
  // is no use: the frames are re-simulated from the start instead.
  if (sf.run_hash != setup_.run_hash || sf.frame != cp.frame) return SnapshotLoad::absent;
  SceneSimulation scratch(ps_);
  if (!scratch.load(sf.snapshot, why) || state_hash(scratch.state()) != cp.state_hash || !sim.load(sf.snapshot, why)) {
    error = (setup_.dir / "state.bin").string() + ": " + (why.empty() ? "its state is not the checkpoint's" : why);
    return SnapshotLoad::damaged;
  }
  max_volume_error = sf.max_volume_error;
  return SnapshotLoad::loaded;
}

// The stress view's range goes with the checkpoint only when the first pass computed it.
Checkpoint RunCheckpoints::at(int frame, const std::string& state_hash) const {
  Checkpoint cp;
  cp.run_hash = setup_.run_hash;
  cp.inputs = setup_.inputs.text();
  cp.frame = frame;
  cp.frames = setup_.frames;
  cp.state_hash = state_hash;
  cp.range_lo = output_.stress_view().lo;
  cp.range_hi = output_.stress_view().hi;
  const RenderDef& rd = ps_.scene.render;
  if (!(setup_.rendering && rd.has(render::View::stress) && rd.range_auto)) cp.range_lo = cp.range_hi = 0;
  return cp;
}

void RunCheckpoints::save_snapshot(int frame, const SceneSimulation& sim, double max_volume_error) {
  StateFile sf{setup_.run_hash, frame, max_volume_error, {}};
  std::string why;
  if (!snapshots_ || !sim.save(sf.snapshot)) return;  // a reference model: resumed by re-simulating
  const fs::path path = setup_.dir / "state.bin";
  if (!write_state_file(path.string(), sf, why)) {
    err_ << "vdmsim: warning: " << why << ": a resume will re-simulate instead\n";
    std::error_code ec;
    fs::remove(path, ec);
    snapshots_ = false;
  }
}

bool RunCheckpoints::write(int frame, const std::string& state_hash, const SceneSimulation& sim, double max_volume_error,
                           std::string& error) {
  const Checkpoint cp = at(frame, state_hash);
  save_snapshot(frame, sim, max_volume_error);
  return write_checkpoint(setup_.checkpoint_path().string(), cp, error);
}

void RunCheckpoints::write_last(int frame, const std::string& state_hash, const SceneSimulation* sim,
                                double max_volume_error) {
  std::string error;
  const Checkpoint cp = at(frame, state_hash);
  std::error_code ec;
  if (sim) save_snapshot(frame, *sim, max_volume_error);
  else fs::remove(setup_.dir / "state.bin", ec);
  if (!write_checkpoint(setup_.checkpoint_path().string(), cp, error)) err_ << "vdmsim: warning: " << error << "\n";
}

}  // namespace vdmsim
