#pragma once
// Runs a sweep's runs on this machine (`vdmsim sweep`'s runs, `vdmsim accuracy`'s
// configurations), N child processes at a time, with one progress line for the whole sweep.
// Ctrl-C (or SIGTERM) stops cleanly: no further run starts, the running ones are told once
// and stop (a scene run after its current frame, run.json: interrupted), to be continued by
// the next `vdmsim sweep`.
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

// The command line of a job's process; `resume`: continue the interrupted run in its folder.
using JobCommand = std::function<std::vector<std::string>(const RunJob& job, bool resume)>;

struct LocalRunSettings {
  std::string label = "sweep";   // what the progress lines start with
  std::string on_stop = "runs finish their current frame";  // what the running jobs do when told to stop
  int parallel = 1;
  bool terminal = false;         // the progress line redrawn in place
  bool forward_signals = true;   // pass a stop signal on to the runs (each in its own process group);
                                 // false: they share the sweep's group, which the signal reaches
                                 // as a whole (a Slurm task cancelled)
  bool quiet = false;            // no progress (a single Slurm task)
};

// Jobs at a time by default: the number of cores.
int default_parallel();

// Runs `jobs`, each as `command` gives it (its output in the folder's run.log). The exit code
// of each job goes to `codes` (by position; -1: not started). A resumed job that exits 2 (its
// checkpoint refused) starts again afresh. False when a stop signal ended the sweep early.
bool run_locally(const std::vector<RunJob>& jobs, const JobCommand& command, const LocalRunSettings& settings,
                 std::vector<int>& codes, std::ostream& err);

}  // namespace vdmsim
