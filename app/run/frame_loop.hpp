#pragma once
// The run's main loop: each frame simulated, its metrics row and mesh file written and its
// pictures handed to the renderer, with a checkpoint every K frames. A resume that could not load a state
// snapshot first re-simulates the frames before its start without writing them.
#include <string>
#include <vector>

#include "app/run/frame_output.hpp"
#include "app/run/mesh_export.hpp"
#include "app/run/metrics_csv.hpp"
#include "app/run/progress.hpp"
#include "app/run/run_checkpoints.hpp"
#include "app/run/run_setup.hpp"
#include "app/run/stop_signals.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {

// How the run went, as run.json reports it.
struct RunOutcome {
  std::string status = "completed";  // completed | interrupted | failed
  std::string reason;                // why not completed
  int done = 0;                      // frames complete (row and pictures)
  int state_frame = -1;              // the last complete frame, whose state the simulation holds
  std::string last_hash;             // the state hash after the last complete frame
  void fail(const std::string& why) {
    status = "failed";
    reason = why;
  }
};

// The step times and volume errors of the frames simulated, and the time spent on metrics.
struct RunTally {
  std::vector<double> step_ms;
  double sum_step = 0, max_step = 0, max_volume_error = 0, io_ms = 0;
  void add_step(double ms);
  double median_step() const;
};

struct FrameLoop {
  const RunSetup& setup;
  const RunOptions& options;
  SceneSimulation& sim;
  MetricsCsv& metrics;
  FrameOutput& output;
  MeshExport& mesh;  // inactive unless --export-mesh
  RunCheckpoints& checkpoints;
  const StopSignals& signals;
  Progress& progress;
  vdm::Clock::time_point run_start;

  // Simulates frames `first` to the end; stops early on a signal or a failure.
  void run(int first, RunTally& tally, RunOutcome& outcome);

 private:
  // Frame f, re-simulated only (already written): checks the checkpoint's state on the way.
  bool replay(int f, RunOutcome& outcome);
  // Frame f's row, mesh file and pictures, then a checkpoint when one is due.
  bool write(int f, RunTally& tally, RunOutcome& outcome);
};

}  // namespace vdmsim
