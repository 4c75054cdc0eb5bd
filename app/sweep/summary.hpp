#pragma once
// A sweep's summary, from what each run folder holds: DIR/summary.csv, one row per run (run,
// status, one column per varied key named exactly as the key, frames, median_step_ms,
// max_volume_rel_error, max_contact_force_n, wall_time_s, reason), and DIR/summary.png, each
// rendered run's deepest-contact frame in a grid, labelled with its values.
#include <filesystem>
#include <string>
#include <vector>

#include "app/sweep/sweep_plan.hpp"

namespace vdmsim {

// One run's outcome. Numbers are kept as the run wrote them (run.json, metrics.csv), so that
// two sweeps of the same runs give the same text.
struct RunResult {
  std::string status;     // completed | interrupted | failed | not run
  std::string reason;     // why not completed ("" when it was)
  std::string frames, median_step_ms, max_volume_rel_error, max_contact_force_n, wall_time_s;
  int deepest_frame = -1;  // the frame of the largest contact force (the last frame when none)
};

// `slurm_log`: the Slurm task's output file, named when a run left nothing else.
RunResult read_run_result(const std::filesystem::path& run_dir, const std::filesystem::path& slurm_log = {});

// A run this sweep ran is failed when its process failed (exit 1, 2, a signal) and interrupted
// when it was stopped (130), whatever its folder's run.json says: a folder another process
// wrote (a run left behind by a killed sweep) is no result of this sweep. -1 (not started) and
// 0 leave `r` as read.
void note_exit_code(RunResult& r, int code, const std::filesystem::path& run_dir);

// The CSV (a field with a comma, a quote or a line break quoted).
std::string summary_csv(const SweepPlan& plan, const std::vector<RunResult>& results);

// The grid of deepest-contact frames of the runs that have pictures. False with `error` (none
// to show is not an error: `written` is false then).
bool write_summary_png(const SweepPlan& plan, const std::vector<RunResult>& results, const std::filesystem::path& dir,
                       bool& written, std::string& error);

}  // namespace vdmsim
