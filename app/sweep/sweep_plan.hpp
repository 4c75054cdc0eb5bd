#pragma once
// A sweep's runs: the grid's combinations (the first axis slowest) or the cases, each with its
// folder name (DIR/runs/<index>_<short name>) and its full scene: the base scene with the
// run's values set and every file path absolute, so that `vdmsim run DIR/runs/.../scene.yaml`
// repeats the run alone.
#include <filesystem>
#include <string>
#include <vector>

#include "app/sweep/sweep_file.hpp"

namespace vdmsim {

struct PlannedRun {
  int index = 0;
  std::string folder;               // "003_bulk_modulus-40000_radius-0.005"
  std::vector<std::string> values;  // per varied key (SweepFile::keys), as written; "" when the run leaves it
  std::vector<std::string> wheres;  // per varied key, where its value is in the sweep file ("" when none)
  std::string scene_text;           // the run's scene.yaml
};

struct SweepPlan {
  std::filesystem::path sweep_file;
  std::vector<std::string> columns;  // the varied keys, as written
  std::vector<PlannedRun> runs;
};

SweepPlan plan_sweep(const SweepFile& sweep);

}  // namespace vdmsim
