#include "app/run/colour_range.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "app/run/scene_field.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {
namespace {

// Widens [lo, hi] to the 0.5 % and 99.5 % quantiles of this frame's field (a handful of nodes
// under an instrument would otherwise set the range and leave the rest of the organ one
// colour; values beyond the range saturate). Contact pressure counts the instruments' contact
// patches only: the fixed nodes' reactions (the organ resting on its support) are many and
// small and would set the range.
void widen_to_frame(const PreparedScene& ps, render::Quantity quantity, std::vector<float>& field, double& lo, double& hi) {
  if (quantity == render::Quantity::contact_pressure) {
    size_t kept = 0;
    for (size_t o = 0; o < ps.organs.size(); ++o) {
      const vdm::FlagMat& held = ps.organs[o].model.held;
      const size_t first = static_cast<size_t>(ps.node_offset[o]);
      for (Eigen::Index i = 0; i < held.rows(); ++i)
        if (field[first + i] > 0.0f && held.row(i).minCoeff() == 0) field[kept++] = field[first + i];
    }
    field.resize(kept);
    if (field.empty()) return;
  }
  const size_t k_lo = field.size() / 200, k_hi = field.size() - 1 - field.size() / 200;
  std::nth_element(field.begin(), field.begin() + k_hi, field.end());
  hi = std::max(hi, double(field[k_hi]));
  std::nth_element(field.begin(), field.begin() + k_lo, field.end());
  lo = std::min(lo, double(field[k_lo]));
}

// The range over every frame of a pass of its own; signed quantities get a range symmetric
// about zero, the others start at zero.
void first_pass_range(const PreparedScene& ps, int frames, render::Quantity quantity, const StopSignals& signals,
                      Progress& progress, double& lo, double& hi) {
  SceneSimulation pass(ps);
  std::vector<float> field;
  progress.restart();
  for (int f = 0; f < frames && !signals.received(); ++f) {
    pass.advance(f);
    if (pass.failed() || !pass.positions().allFinite()) break;
    scene_scalar_field(quantity, pass, field);
    widen_to_frame(ps, quantity, field, lo, hi);
    progress.show("colour range", f + 1, frames);
  }
  progress.end_line();
  if (render::quantity_is_signed(quantity)) {
    const double a = std::max(std::abs(lo), std::abs(hi));
    lo = -a;
    hi = a;
  } else {
    lo = 0;
  }
  if (!(hi > lo)) hi = lo + 1e-12 + std::abs(lo) * 1e-6;
}

}  // namespace

double set_auto_colour_range(const PreparedScene& ps, const RunSetup& setup, FrameOutput& output,
                             const StopSignals& signals, Progress& progress) {
  const RenderDef& rd = ps.scene.render;
  if (!(setup.rendering && rd.has(render::View::stress) && rd.range_auto)) return 0;
  const Checkpoint& cp = setup.resume_from;
  if (setup.resume && cp.range_lo < cp.range_hi) {
    output.set_stress_range(cp.range_lo, cp.range_hi);  // the interrupted run's range
    return 0;
  }
  const auto t0 = vdm::Clock::now();
  double lo = 0, hi = 0;
  first_pass_range(ps, setup.frames, output.stress_view().quantity, signals, progress, lo, hi);
  output.set_stress_range(lo, hi);
  return vdm::ms_since(t0);
}

}  // namespace vdmsim
