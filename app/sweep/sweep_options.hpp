#pragma once
// `vdmsim sweep`'s options, and the runs it starts: each `vdmsim run` of a run folder.
#include <filesystem>
#include <string>
#include <vector>

#include "app/run/scene_run.hpp"
#include "app/sweep/run_folder.hpp"

namespace vdmsim {

struct SweepOptions {
  std::string sweep_file;
  std::string out_dir;
  int jobs = 0;             // local runs at a time; 0: the number of cores
  bool slurm = false;       // submit a Slurm job array instead
  std::string partition;    // --slurm: the partition ("": the cluster's default)
  int max_parallel = 0;     // --slurm: array tasks at a time (0: all)
  int frames = -1;          // each run's frame count, when > 0
  bool render = true;
  bool video = false;
  int task = -1;            // run only this run (a Slurm array task)
};

// The options every run of the sweep gets (frames, rendering, video).
RunOptions run_options(const SweepOptions& options);

// A run to do: its folder and what it holds.
struct RunJob {
  int index = 0;
  std::filesystem::path dir;
  RunFolderState state = RunFolderState::fresh;
};

// `program run DIR/scene.yaml --out DIR ...` for a job, continuing it when `resume`.
std::vector<std::string> run_command(const std::string& program, const RunJob& job, const SweepOptions& options,
                                     bool resume);

}  // namespace vdmsim
