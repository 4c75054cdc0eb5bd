#pragma once
// The stress view's quantity over every organ of a scene, in the node order of the surface the
// picture draws (PreparedScene::surface: the organs one after another).
#include <vector>

#include "app/simulation/scene_simulation.hpp"
#include "render/render_scene.hpp"

namespace vdmsim {

void scene_scalar_field(render::Quantity quantity, const SceneSimulation& sim, std::vector<float>& out);

}  // namespace vdmsim
