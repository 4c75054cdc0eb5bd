#include "render/gizmo.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "render/imgui_layer.hpp"

namespace render {

std::array<GizmoAxis, 3> gizmo_axes(const Camera& camera) {
  // The camera's frame as look_at builds it (another up when the view is along `up`).
  const Eigen::Vector3d forward = (camera.target - camera.eye).normalized();
  Eigen::Vector3d up = camera.up;
  if (forward.cross(up).norm() < 1e-9) up = std::abs(forward.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d side = forward.cross(up).normalized(), screen_up = side.cross(forward);
  std::array<GizmoAxis, 3> axes;
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
    axes[size_t(a)] = {a, e.dot(side), -e.dot(screen_up), e.dot(forward)};
  }
  std::stable_sort(axes.begin(), axes.end(), [](const GizmoAxis& p, const GizmoAxis& q) { return p.away > q.away; });
  return axes;
}

void draw_gizmo(ImDrawList* dl, const ImGuiLayer& layer, const Camera& camera, int width, int height) {
  (void)width;
  ImFont* font = layer.font(FontRole::small);
  const float fs = layer.font(FontRole::body)->FontSize;
  // A disc with room for the axes and their labels, a margin from the corner.
  const float length = fs * 2.4f, margin = fs * 0.6f, disc = length + fs * 1.1f;
  const ImVec2 centre(margin + disc, height - margin - disc);
  dl->AddCircleFilled(centre, disc, IM_COL32(20, 22, 26, 120), 48);
  const ImU32 colours[3] = {IM_COL32(228, 72, 64, 255), IM_COL32(96, 196, 88, 255), IM_COL32(84, 140, 240, 255)};
  const char* names[3] = {"x", "y", "z"};
  for (const GizmoAxis& g : gizmo_axes(camera)) {
    const ImVec2 end(centre.x + float(g.dx) * length, centre.y + float(g.dy) * length);
    dl->AddLine(centre, end, colours[g.axis], std::max(2.0f, fs * 0.16f));
    dl->AddCircleFilled(end, std::max(2.0f, fs * 0.16f), colours[g.axis], 12);
    // The label just beyond the axis's end, centred on the line's direction.
    const double len = std::hypot(g.dx, g.dy);
    const ImVec2 size = text_size(font, names[g.axis]);
    const float ux = len > 1e-6 ? float(g.dx / len) : 0.0f, uy = len > 1e-6 ? float(g.dy / len) : -1.0f;
    const ImVec2 at(end.x + ux * fs * 0.55f - size.x * 0.5f, end.y + uy * fs * 0.55f - size.y * 0.5f);
    draw_text(dl, font, at, colours[g.axis], names[g.axis]);
  }
}

}  // namespace render
