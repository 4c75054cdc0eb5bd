#pragma once
// One run's folder in a sweep (DIR/runs/<index>_<name>/): its scene.yaml, the usual outputs of
// `vdmsim run`, and run.log (what the run printed). What a sweep does with it follows from
// what is there: a finished run of the same inputs is kept, an interrupted one continued
// (`vdmsim run --resume`), anything else run afresh.
#include <filesystem>
#include <string>

#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"

namespace vdmsim {

// Opens a sweep's (or study's) folder: `out` made absolute into `dir`, DIR/runs created, and
// the folder locked for this sweep unless `task` (a task works in its own run folder only).
// False with `error`.
bool open_sweep_dir(const std::string& out, bool task, std::filesystem::path& dir, OutputLock& lock,
                    std::string& error);

enum class RunFolderState {
  finished,     // completed, of this scene, its files and these options: nothing to do
  resumable,    // interrupted (or killed) after a checkpoint of these inputs: continue it
  fresh,        // none, failed, or of other inputs: run it afresh
};
const char* to_string(RunFolderState s);

// Writes the run's scene.yaml when it differs from `scene_text`; results of the earlier scene
// (run.json, checkpoint, run.log) go with it. False with `error`.
bool write_run_scene(const std::filesystem::path& dir, const std::string& scene_text, std::string& error);

// What the folder holds, for a run with `options` (frames, rendering, video). Results of other
// inputs (a changed mesh, another program) are removed.
RunFolderState run_folder_state(const std::filesystem::path& dir, const RunOptions& options);

// Removes a run's results before it runs afresh (scene.yaml stays).
void clear_run_results(const std::filesystem::path& dir);

}  // namespace vdmsim
