#pragma once
// DIR/run.json: what a run did (scene, status, frames, model, effects), how long its stages
// took, what it rendered and the simulation's warnings.
#include <filesystem>
#include <string>
#include <vector>

#include "app/run/frame_loop.hpp"

namespace vdmsim {

struct RunRecord {
  RunRecord(const PreparedScene& p, const RunSetup& s, const RunOutcome& o, const RunTally& t, const FrameOutput& out)
      : prepared(p), setup(s), outcome(o), tally(t), output(out) {}
  const PreparedScene& prepared;
  const RunSetup& setup;
  const RunOutcome& outcome;
  const RunTally& tally;
  const FrameOutput& output;
  const MeshExport* mesh = nullptr;  // --export-mesh's files (inactive when not asked)
  bool resumed_by_snapshot = false;
  StageTimes stage_times;
  std::vector<std::string> warnings;
  bool forces = false;                    // the instruments' forces were measured (contact or grasp)
  std::vector<double> peak_forces;        // per instrument (N)
  std::vector<double> organ_max_volume_errors;  // per organ: its largest |volume_rel_error|
  long contact_iterations = 0, unconverged_contact_steps = 0;
  double wall_s = 0, colour_range_ms = 0;
  std::string video_status;
};

std::string run_json(const RunRecord& record);

}  // namespace vdmsim
