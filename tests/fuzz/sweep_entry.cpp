// The sweep-file fuzz entry (fuzz_entries.hpp). Kept apart from the scene and mesh entries so
// that fuzz_sweep links only the sweep reader, the scene reader and what they use (no mesh
// readers, no CGAL): cheap enough to build and run in CI.
#include <unistd.h>

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "app/sweep/sweep_file.hpp"
#include "app/sweep/sweep_plan.hpp"
#include "fuzz/fuzz_entries.hpp"

namespace vdmsim::fuzz {
namespace {

namespace fs = std::filesystem;

// Plans of more runs than this are not made (each run clones the base scene: time, not bugs).
constexpr double kMaxPlannedRuns = 200;

// A folder of this process's with the base scene and its organ (an octahedron), made once.
const fs::path& sweep_folder() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("vdmsim_fuzz_sweep_" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::ofstream(d / "organ.obj") << "v 0.05 0 0\nv -0.05 0 0\nv 0 0.05 0\nv 0 -0.05 0\nv 0 0 0.05\nv 0 0 -0.05\n"
                                      "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
    std::ofstream(d / "base.yaml") << "name: base\norgan:\n  mesh: organ.obj\n  material: {bulk_modulus: 20000, "
                                      "connectivity_modulus: 2000}\n  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, 0]}}]\n"
                                      "simulation: {frames: 2, dt: 0.1, effects: [contact]}\ninstruments:\n  - {type: "
                                      "probe, radius: 0.004, script: [{t: 0, tip: [0, 0, 0.1], axis: [0, 0, -1]}]}\n";
    return d;
  }();
  return dir;
}

}  // namespace

void sweep_input(const std::uint8_t* data, std::size_t size) {
  const fs::path file = sweep_folder() / "sweep.yaml";
  if (FILE* f = std::fopen(file.c_str(), "wb")) {
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  SweepFile sweep;
  std::vector<SceneProblem> problems;
  const bool ok = read_sweep_file(file.string(), sweep, problems);
  for (const SceneProblem& p : problems) (void)p.text();
  if (!ok) return;
  double runs = sweep.axes.empty() ? double(sweep.cases.size()) : 1.0;
  for (const SweepAxis& a : sweep.axes) runs *= double(a.size());
  if (runs > kMaxPlannedRuns) return;
  // The keys a run's scene may have at its top: the base's, and the first step of a varied key.
  std::set<std::string> allowed;
  for (auto it = sweep.base_yaml.begin(); it != sweep.base_yaml.end(); ++it) allowed.insert(it->first.Scalar());
  for (const SweepKey& k : sweep.keys) allowed.insert(k.path.steps.front().name);
  for (const PlannedRun& run : plan_sweep(sweep).runs) {
    YAML::Node scene;
    try {
      scene = YAML::Load(run.scene_text);
    } catch (const YAML::Exception&) {
      std::abort();  // the sweep wrote a scene that is no YAML
    }
    if (!scene.IsMap()) std::abort();
    for (auto it = scene.begin(); it != scene.end(); ++it)
      if (!allowed.count(it->first.Scalar())) std::abort();  // a value became a key of the scene
  }
}

}  // namespace vdmsim::fuzz
