#pragma once
// The HUD panel's text (render-internal, no drawing): the lines under the scene's name.
#include <string>
#include <vector>

#include "render/render_scene.hpp"

namespace render {

// Frame and time, contact force, fluid pressure (the model's internal pressure), volume error,
// and the step time when asked. Values within round-off of zero (zero_if_roundoff, by the
// scales in `hud`) read 0.
std::vector<std::string> hud_lines(const HudInfo& hud);

}  // namespace render
