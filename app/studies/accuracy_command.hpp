#pragma once
// `vdmsim accuracy`: the study's configurations as runs of the sweep machinery. Each
// configuration's scene goes to DIR/runs/<index>_<name>/; the ones without a result of that
// scene run as tasks (`vdmsim accuracy --out DIR --task I`), on this machine N at a time or as
// one Slurm job array; then accuracy.csv, accuracy.png and recommendations.md are built from
// what the tasks left. Run again, the study runs only what is missing.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "app/studies/accuracy.hpp"

namespace vdmsim {

// Returns the exit code: 0, 1 (a failure at run time: the reference failed, the array could not
// be submitted, a file not written), 2 (bad options, a folder not writable), 130 (stopped).
int run_accuracy(const AccuracyOptions& options, std::ostream& out, std::ostream& err, bool terminal);

// A run folder's name: the index, three digits at least, and the name ("007_probe_poke_...").
std::string numbered_folder(int index, const std::string& name);

// The project's liver at `levels`, in DIR/meshes (only the missing ones when `missing_only`),
// and the timing yardstick's scene, DIR/yardstick.yaml. Each file is written whole under
// another name, then renamed: tasks that start together never read half a file.
bool write_study_meshes(const std::filesystem::path& dir, std::vector<int> levels, bool quick, bool missing_only,
                        std::string& error);

}  // namespace vdmsim
