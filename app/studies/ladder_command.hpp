#pragma once
// `vdmsim accuracy --ladder`: the model ladder's rungs (ladder.hpp) as the accuracy study's
// tasks. Each rung's folder is DIR/ladder/<index>_<name>/, holding its scene.yaml (the liver
// probe) or rung.txt (a load case: what it runs); the rungs without a result of those run as
// tasks (`vdmsim accuracy --ladder --out DIR --task I`), here N at a time or as one Slurm job
// array, each followed by the timing yardstick in its process; then ladder.csv and ladder.png.
#include <ostream>

#include "app/studies/accuracy.hpp"

namespace vdmsim {

// The exit code, as run_accuracy's.
int run_ladder(const AccuracyOptions& options, std::ostream& out, std::ostream& err, bool terminal);

}  // namespace vdmsim
