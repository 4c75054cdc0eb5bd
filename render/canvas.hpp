#pragma once
// An offscreen 2D canvas (render-internal): its own GL context and ImGui layer; draw with
// ImGui draw lists, read back an Image. Used by plots and the contact sheet.
#include <memory>
#include <string>

#include "render/gl_context.hpp"
#include "render/imgui_layer.hpp"

namespace render {

class Canvas {
 public:
  static std::unique_ptr<Canvas> create(float body_px, std::string& error);
  ~Canvas();
  // Starts a drawing of width x height cleared to `background` (RGB 0-1).
  ImDrawList* begin(int width, int height, float r, float g, float b);
  Image end();
  ImGuiLayer& layer() { return imgui_; }

 private:
  std::unique_ptr<GlContext> gl_;
  std::unique_ptr<Framebuffer> fb_;
  ImGuiLayer imgui_;
};

}  // namespace render
