#include "app/run/scene_field.hpp"

namespace vdmsim {

void scene_scalar_field(render::Quantity quantity, const SceneSimulation& sim, std::vector<float>& out) {
  if (sim.organ_count() == 1) {
    render::scalar_field(quantity, sim.state(), out);
    return;
  }
  out.clear();
  std::vector<float> organ;
  for (size_t i = 0; i < sim.organ_count(); ++i) {
    render::scalar_field(quantity, sim.state(i), organ);
    out.insert(out.end(), organ.begin(), organ.end());
  }
}

}  // namespace vdmsim
