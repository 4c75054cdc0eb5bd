#pragma once
// The heads-up display drawn over each frame (render-internal): a panel with the scene name,
// frame and time, contact force, fluid pressure, volume error and step time; in the stress view a
// colour bar with ticks and units.
#include <string>
#include <vector>

#include "render/hud_text.hpp"
#include "render/imgui_layer.hpp"
#include "render/number_format.hpp"
#include "render/render_scene.hpp"

namespace render {

struct StressView;

void draw_hud(ImDrawList* dl, const ImGuiLayer& layer, const HudInfo& hud, int width, int height,
              const StressView* stress);

}  // namespace render
