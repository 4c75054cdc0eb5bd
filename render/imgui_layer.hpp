#pragma once
// Dear ImGui on an offscreen GL context (render-internal): one ImGui context with the
// OpenGL3 backend, DejaVu Sans at three sizes, and 2D drawing through draw lists (no
// windows, so nothing depends on ImGui's window state from frame to frame).
#include <imgui.h>

#include <string>
#include <vector>

#include "render/image.hpp"

namespace render {

enum class FontRole { body, small, title };

class ImGuiLayer {
 public:
  ImGuiLayer() = default;
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;
  // Needs the GL context current. `body_px`: body text height in pixels.
  bool init(float body_px, std::string& error);
  // Starts a frame of the given size; returns the draw list to draw on (front-most layer).
  ImDrawList* begin(int width, int height);
  // Renders the frame's draw lists into the currently bound framebuffer.
  void end();
  // The pixel rectangle [x0, x1) x [y0, y1) (y down, ImGui's) that the last frame's draw
  // lists touch (with a pixel of margin), clipped to the frame; false when nothing was drawn.
  bool drawn_bounds(int& x0, int& y0, int& x1, int& y1) const;
  ImFont* font(FontRole role) const;
  // Uploads `image` as a texture usable with ImDrawList::AddImage, valid until the next
  // clear_textures().
  ImTextureID texture(const Image& image);
  void clear_textures();

 private:
  ImGuiContext* context_ = nullptr;
  ImFont* fonts_[3] = {nullptr, nullptr, nullptr};
  std::vector<unsigned> textures_;
  bool backend_ = false;
};

// Text measurement and drawing helpers on a draw list.
ImVec2 text_size(ImFont* font, const std::string& text);
void draw_text(ImDrawList* dl, ImFont* font, ImVec2 pos, ImU32 colour, const std::string& text);

}  // namespace render
