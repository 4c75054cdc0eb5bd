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

namespace {

// Each organ alone with the other following (runs 3 and 4), at its cost per iteration there,
// over as many iterations as it took in the two-organ run (ms).
double alone_at_together_iterations(const OrgansSideBySide& r, const double* t) {
  double sum = 0;
  for (int i = 0; i < 2; ++i) {
    const long its = r.iterations[3 + i];
    if (its > 0) sum += t[3 + i] / static_cast<double>(its) * static_cast<double>(r.iterations_together[i]);
  }
  return sum;
}

}  // namespace

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
  // Per organ of the two-organ run, per frame and sub-step: its surface (recorded in the first
  // round; the runs are deterministic). Runs 3 and 4 are the scene with one organ simulated
  // (3 the liver, 4 the gallbladder) and the other following its recorded surface.
  SceneSimulation::SubstepSurfaces surfaces[2];
  std::vector<double> total[kRuns], ratios, replayed_ratios, per_iteration_ratios;
  for (int round = 0; round < rounds; ++round) {
    double t[kRuns] = {};
    for (int k = 0; k < kRuns; ++k) {
      SceneSimulation sim(ps[k < 3 ? k : 0]);
      if (k == 3) sim.follow_recorded_surface(1, &surfaces[1]);
      if (k == 4) sim.follow_recorded_surface(0, &surfaces[0]);
      if (k == 0 && round == 0)
        for (size_t i = 0; i < 2; ++i) sim.record_organ_surface(i, &surfaces[i]);
      long iterations = 0;
      for (int f = 0; f < r.frames; ++f) {
        sim.advance(f);
        if (!sim.unsound().empty()) throw std::runtime_error("organs side by side: " + sim.unsound());
        t[k] += sim.frame_step_ms();
        iterations += sim.frame_iterations();
      }
      total[k].push_back(t[k]);
      r.iterations[k] = iterations;
      r.unconverged[k] = sim.unconverged_contact_steps();
      // The replayed organ's last surface against the two-organ run's: the same deformation?
      if (k >= 3 && !surfaces[k - 3].empty() && !surfaces[k - 3].back().empty())
        r.replayed_apart_m[k - 3] = (sim.state(static_cast<size_t>(k - 3)).x - surfaces[k - 3].back().back()).cwiseAbs().maxCoeff();
      if (k == 0)
        for (size_t i = 0; i < 2; ++i) r.iterations_together[i] = sim.organ_iterations(i);
    }
    ratios.push_back(t[0] / (t[1] + t[2]));
    replayed_ratios.push_back(t[0] / (t[3] + t[4]));
    per_iteration_ratios.push_back(t[0] / alone_at_together_iterations(r, t));
  }
  for (int k = 0; k < kRuns; ++k) r.total_ms[k] = quantile(total[k], 0.5);
  r.ratio = r.total_ms[0] / (r.total_ms[1] + r.total_ms[2]);
  r.ratio_min = *std::min_element(ratios.begin(), ratios.end());
  r.ratio_max = *std::max_element(ratios.begin(), ratios.end());
  r.replayed_ratio = r.total_ms[0] / (r.total_ms[3] + r.total_ms[4]);
  r.replayed_ratio_min = *std::min_element(replayed_ratios.begin(), replayed_ratios.end());
  r.replayed_ratio_max = *std::max_element(replayed_ratios.begin(), replayed_ratios.end());
  r.per_iteration_ratio = r.total_ms[0] / alone_at_together_iterations(r, r.total_ms);
  r.per_iteration_ratio_min = *std::min_element(per_iteration_ratios.begin(), per_iteration_ratios.end());
  r.per_iteration_ratio_max = *std::max_element(per_iteration_ratios.begin(), per_iteration_ratios.end());
  return r;
}

}  // namespace vdmsim
