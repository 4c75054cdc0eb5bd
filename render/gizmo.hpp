#pragma once
// The orientation gizmo (render.gizmo): the world's x, y and z axes as the camera sees them,
// drawn small in the bottom-left corner, red, green and blue, each labelled.
#include <array>

#include "render/camera.hpp"

struct ImDrawList;

namespace render {

class ImGuiLayer;

// One world axis on screen: its direction in the picture (x right, y down; length 1 for an
// axis across the view, shorter as it turns toward or away from the camera) and how far it
// points away from the camera (the axes are drawn farthest first).
struct GizmoAxis {
  int axis = 0;  // 0 x, 1 y, 2 z
  double dx = 0, dy = 0;
  double away = 0;
};

// The three axes for `camera`, farthest first.
std::array<GizmoAxis, 3> gizmo_axes(const Camera& camera);

void draw_gizmo(ImDrawList* dl, const ImGuiLayer& layer, const Camera& camera, int width, int height);

}  // namespace render
