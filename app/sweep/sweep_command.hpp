#pragma once
// `vdmsim sweep SWEEP.yaml --out DIR`: reads and checks the sweep file, writes every run's
// scene into DIR/runs/<index>_<name>/, runs what is not finished (on this machine, or as a
// Slurm job array), then writes DIR/summary.csv and DIR/summary.png. With --task I it runs
// run I only (what each array task does). Exit codes: 0 every run completed, 1 a run failed,
// 2 bad input, 130 stopped (Ctrl-C).
#include <ostream>

#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

int cmd_sweep(const SweepOptions& options, std::ostream& out, std::ostream& err, bool terminal);

}  // namespace vdmsim
