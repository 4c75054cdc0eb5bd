#pragma once
// Runs a sweep's runs on this machine, N child processes at a time, with one progress line for
// the whole sweep. Ctrl-C (or SIGTERM) stops cleanly: no further run starts, the running ones
// are told once and stop after their current frame (run.json: interrupted), to be continued
// by the next `vdmsim sweep`.
#include <ostream>
#include <vector>

#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

struct LocalRunSettings {
  int parallel = 1;
  bool terminal = false;         // the progress line redrawn in place
  bool forward_signals = true;   // pass a stop signal on to the runs (each in its own process group);
                                 // false: they share the sweep's group, which the signal reaches
                                 // as a whole (a Slurm task cancelled)
  bool quiet = false;            // no progress (a single Slurm task)
};

// Runs `jobs` (their runs' output in each folder's run.log). The exit code of each job's run
// goes to `codes` (by position; -1: not started). False when a stop signal ended the sweep early.
bool run_locally(const std::vector<RunJob>& jobs, const SweepOptions& options, const LocalRunSettings& settings,
                 std::vector<int>& codes, std::ostream& err);

}  // namespace vdmsim
