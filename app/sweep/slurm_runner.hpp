#pragma once
// Runs a sweep's runs on a Slurm cluster: one job array (`sbatch --array=<indices>%K`) whose
// task I runs the task command with `--task I` (`vdmsim sweep SWEEP.yaml --out DIR --task I`,
// `vdmsim accuracy --out DIR --task I`: the same program, on a shared file system), then waits
// for the array to leave the queue (squeue). Ctrl-C cancels the array (scancel): its runs
// stop, to be continued by the next sweep.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "app/sweep/sweep_options.hpp"

namespace vdmsim {

// The array's index list for sbatch: consecutive indices as ranges ("0-3,5,7-8").
std::string array_indices(const std::vector<int>& indices);

// What the job array runs and where.
struct SlurmArray {
  std::string name = "sweep";             // the job's name is vdmsim-<name>, its script DIR/slurm/<name>.sbatch
  std::string what;                       // the script's comment line: what the array does
  std::vector<std::string> task_command;  // a task's command line, before `--task I`
  std::string partition;                  // "": the cluster's default
  int max_parallel = 0;                   // tasks running at a time (0: all)
};

// The batch script for the jobs (DIR/slurm/<name>.sbatch).
std::string batch_script(const std::vector<RunJob>& jobs, const SlurmArray& array, const std::filesystem::path& dir);

// Submits and waits. 0 when the array ran (each task's outcome is in its run folder), 130 when
// a stop signal cancelled it, 1 when it could not be submitted (the message on `err`).
int run_on_slurm(const std::vector<RunJob>& jobs, const SlurmArray& array, const std::filesystem::path& dir,
                 std::ostream& err);

// `vdmsim sweep`'s array: each task runs `vdmsim sweep SWEEP --out DIR` with the sweep's options.
SlurmArray sweep_array(const SweepOptions& options, const std::filesystem::path& dir);

}  // namespace vdmsim
