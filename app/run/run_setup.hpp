#pragma once
// What a scene run starts from: the frame count, the output folder and whether it renders,
// checked against the options; and, when resuming, the checkpoint it continues from.
#include <filesystem>
#include <vector>
#include <memory>
#include <ostream>
#include <string>

#include "app/run/checkpoint.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"

namespace vdmsim {

struct RunSetup {
  int frames = 0;
  std::filesystem::path dir;
  bool rendering = false;     // the scene has views and the options render them
  bool resume = false;
  RunInputs inputs;           // what the result depends on (the scene, its files, options, program)
  std::string run_hash;       // inputs.hash()
  Checkpoint resume_from;     // when resuming: the interrupted run's last checkpoint
  int start = 0;              // the first frame to write
  std::vector<std::string> organs;  // the organs' names (they name --export-mesh's files)
  std::filesystem::path checkpoint_path() const { return dir / "checkpoint.json"; }
  std::shared_ptr<OutputLock> lock;  // the folder, owned for the whole run
};

// The frames a run of `scene` with `options` simulates, whether it renders, and everything its
// result depends on (the scene file, the files it loads, the options that change results and
// the program): RunInputs::hash() is the run hash its checkpoints carry. `vdmsim sweep` tells
// from it whether a run folder already holds this run.
int run_frames(const SceneDef& scene, const RunOptions& options);
bool run_renders(const SceneDef& scene, const RunOptions& options);
RunInputs run_inputs(const SceneDef& scene, const RunOptions& options);

// Checks the options, prepares the output folder (a fresh run removes an earlier run's
// outputs there) and, when resuming, reads and checks the checkpoint. Notes on stderr for
// instruments whose effect the scene does not list. Returns -1 when the run goes on,
// otherwise its exit code (after a message on `err`).
int set_up_run(const PreparedScene& prepared, const RunOptions& options, RunSetup& setup, std::ostream& err);

}  // namespace vdmsim
