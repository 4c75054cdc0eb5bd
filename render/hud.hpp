#pragma once
// The heads-up display drawn over each frame (render-internal): a panel with the scene name,
// frame and time, contact force, pressure, volume error and step time; in the stress view a
// colour bar with ticks and units. Also number formatting and axis ticks shared with plots.
#include <string>
#include <vector>

#include "render/imgui_layer.hpp"
#include "render/render_scene.hpp"

namespace render {

struct StressView;

void draw_hud(ImDrawList* dl, const ImGuiLayer& layer, const HudInfo& hud, int width, int height,
              const StressView* stress);

// "Nice" tick values (1, 2, 5 x 10^k) covering [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target);
// A display unit for values up to `magnitude` of an SI unit: {scale, label}; e.g. Pa with
// 4000 -> {1e-3, "kPa"}, m with 0.02 -> {1e3, "mm"}.
std::pair<double, std::string> display_unit(const std::string& si_unit, double magnitude);
// A compact number: up to `digits` significant digits, no trailing zeros.
std::string format_number(double v, int digits = 3);

}  // namespace render
