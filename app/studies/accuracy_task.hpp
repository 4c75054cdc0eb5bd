#pragma once
// One configuration of the accuracy study in its run folder (DIR/runs/<index>_<name>/): its
// scene.yaml, and once its task has run, trajectory.bin (accuracy_trajectory.hpp), run.json
// (status, the inputs it ran, the yardstick's time, why it failed) and run.log. The task
// (`vdmsim accuracy --task I`, locally or as a Slurm array task) simulates the configuration,
// then the timing yardstick in the same process: their ratio compares across nodes, their
// milliseconds do not.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

#include "app/studies/accuracy_trajectory.hpp"

namespace vdmsim {

// What the configuration's result depends on (its scene, the meshes it loads, the program),
// as a hash; "" when the scene does not load.
std::string config_inputs_hash(const std::filesystem::path& scene);

// True when the folder holds a completed result of its scene.yaml as it is now.
bool config_finished(const std::filesystem::path& run_dir);

// True when the folder holds a completed result whose inputs hash is `inputs` (not empty).
bool task_finished(const std::filesystem::path& run_dir, const std::string& inputs);

// A task's own simulation (a scene's, or a load case's for the model ladder); a failure is
// returned as `failed` with the reason.
using TaskSimulation = std::function<Trajectory()>;

// Runs `simulate`, then the yardstick scene in the same process, and writes the results to
// `run_dir` (trajectory.bin; run.json with `inputs`, the yardstick's time or why it failed).
// 0 when completed, 1 when it failed.
int run_task(const std::filesystem::path& run_dir, const std::string& inputs, const TaskSimulation& simulate,
             const std::filesystem::path& yardstick_scene, std::ostream& out);

// Simulates the configuration of `run_dir`/scene.yaml, then the yardstick scene, and writes
// the results (an earlier result removed first; run.log, where the task's output may go, stays). 0 when completed, 1 when the configuration failed (run.json says why).
int run_config_task(const std::filesystem::path& run_dir, const std::filesystem::path& yardstick_scene,
                    std::ostream& out);

// What a configuration's task left: "completed" with its trajectory and yardstick time,
// "failed" with the reason, or "not run" (nothing there, or a task that did not finish).
struct ConfigResult {
  std::string status = "not run";
  std::string reason;
  double yardstick_ms = 0;
  Trajectory trajectory;
};
ConfigResult read_config_result(const std::filesystem::path& run_dir);

}  // namespace vdmsim
