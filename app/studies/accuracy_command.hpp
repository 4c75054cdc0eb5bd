#pragma once
// `vdmsim accuracy`: the study's configurations as runs of the sweep machinery. Each
// configuration's scene goes to DIR/runs/<index>_<name>/; the ones without a result of that
// scene run as tasks (`vdmsim accuracy --out DIR --task I`), on this machine N at a time or as
// one Slurm job array; then accuracy.csv, accuracy.png and recommendations.md are built from
// what the tasks left. Run again, the study runs only what is missing.
#include <ostream>

#include "app/studies/accuracy.hpp"

namespace vdmsim {

// Returns the exit code: 0, 1 (a failure at run time: the reference failed, the array could not
// be submitted, a file not written), 2 (bad options, a folder not writable), 130 (stopped).
int run_accuracy(const AccuracyOptions& options, std::ostream& out, std::ostream& err, bool terminal);

}  // namespace vdmsim
