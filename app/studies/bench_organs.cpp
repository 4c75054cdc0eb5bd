#include "app/studies/bench_organs.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/install/install_paths.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "app/studies/quantile.hpp"

namespace fs = std::filesystem;

namespace vdmsim {

OrgansSideBySide bench_organs_side_by_side(int frames, int rounds) {
  const std::string path = (fs::path(data_dir()) / "scenes" / "gallbladder_retraction.yaml").string();
  SceneLoadResult loaded = load_scene(path);
  if (!loaded.ok()) throw std::runtime_error(path + ": cannot load");
  OrgansSideBySide r;
  r.frames = std::min(frames, loaded.scene.frames);
  r.rounds = rounds;
  PreparedScene ps[3];
  for (int k = 0; k < 3; ++k) {
    SceneDef s = loaded.scene;
    s.frames = r.frames;
    s.has_render = false;
    s.effects.erase(std::remove(s.effects.begin(), s.effects.end(), Effect::stress), s.effects.end());
    if (k > 0) {  // one organ alone: 1 the liver, 2 the gallbladder
      s.organs = {s.organs[static_cast<size_t>(k - 1)]};
      s.attachments.clear();
    }
    std::vector<SceneProblem> problems;
    if (!prepare_scene_def(s, ps[k], problems))
      throw std::runtime_error(problems.empty() ? "cannot prepare " + path : problems.back().text());
    r.nodes[k] = static_cast<long>(ps[k].surface.positions.rows());
  }
  constexpr int kRuns = OrgansSideBySide::kRuns;
  // Per organ of the two-organ run, per frame and sub-step: the forces the other organ put on
  // it (recorded in the first round; the runs are deterministic).
  SceneSimulation::SubstepForces other_forces[2];
  std::vector<double> total[kRuns], ratios, replayed_ratios;
  for (int round = 0; round < rounds; ++round) {
    double t[kRuns] = {};
    for (int k = 0; k < kRuns; ++k) {
      SceneSimulation sim(ps[k < 3 ? k : k - 2]);
      if (k >= 3) sim.replay_forces(0, &other_forces[k - 3]);
      if (k == 0 && round == 0)
        for (size_t i = 0; i < 2; ++i) sim.record_organ_forces(i, &other_forces[i]);
      long iterations = 0;
      for (int f = 0; f < r.frames; ++f) {
        sim.advance(f);
        if (!sim.unsound().empty()) throw std::runtime_error("organs side by side: " + sim.unsound());
        t[k] += sim.frame_step_ms();
        iterations += sim.frame_iterations();
      }
      total[k].push_back(t[k]);
      r.iterations[k] = iterations;
    }
    ratios.push_back(t[0] / (t[1] + t[2]));
    replayed_ratios.push_back(t[0] / (t[3] + t[4]));
  }
  for (int k = 0; k < kRuns; ++k) r.total_ms[k] = quantile(total[k], 0.5);
  r.ratio = r.total_ms[0] / (r.total_ms[1] + r.total_ms[2]);
  r.ratio_min = *std::min_element(ratios.begin(), ratios.end());
  r.ratio_max = *std::max_element(ratios.begin(), ratios.end());
  r.replayed_ratio = r.total_ms[0] / (r.total_ms[3] + r.total_ms[4]);
  r.replayed_ratio_min = *std::min_element(replayed_ratios.begin(), replayed_ratios.end());
  r.replayed_ratio_max = *std::max_element(replayed_ratios.begin(), replayed_ratios.end());
  return r;
}

}  // namespace vdmsim
