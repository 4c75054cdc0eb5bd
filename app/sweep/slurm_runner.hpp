#pragma once
// Runs a sweep's runs on a Slurm cluster: one job array (`sbatch --array=<indices>%K`) whose
// task I runs `vdmsim sweep SWEEP.yaml --out DIR --task I` (the same program, on a shared
// file system), then waits for the array to leave the queue (squeue). Ctrl-C cancels the
// array (scancel): its runs stop after their current frame, to be continued by the next sweep.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

// The array's index list for sbatch: consecutive indices as ranges ("0-3,5,7-8").
std::string array_indices(const std::vector<int>& indices);

// The batch script for the jobs (DIR/slurm/sweep.sbatch).
std::string batch_script(const std::vector<RunJob>& jobs, const SweepOptions& options, const std::filesystem::path& dir,
                         const std::string& program);

// Submits and waits. 0 when the array ran (each task's outcome is in its run folder), 130 when
// a stop signal cancelled it, 1 when it could not be submitted (the message on `err`).
int run_on_slurm(const std::vector<RunJob>& jobs, const SweepOptions& options, const std::filesystem::path& dir,
                 std::ostream& err);

}  // namespace vdmsim
