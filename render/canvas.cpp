#include "render/canvas.hpp"

#include <GL/gl.h>

namespace render {

std::unique_ptr<Canvas> Canvas::create(float body_px, std::string& error) {
  std::unique_ptr<Canvas> c(new Canvas());
  c->gl_ = GlContext::create(error);
  if (!c->gl_) return nullptr;
  if (!c->imgui_.init(body_px, error)) return nullptr;
  return c;
}

Canvas::~Canvas() {
  if (gl_) gl_->make_current();  // the layer and framebuffer free GL objects
}

ImDrawList* Canvas::begin(int width, int height, float r, float g, float b) {
  gl_->make_current();
  // 4x MSAA, no depth buffer (2D drawing: a sheet of twelve 720p thumbnails saves 15 MB).
  if (!fb_ || fb_->width() != width || fb_->height() != height)
    fb_ = std::make_unique<Framebuffer>(width, height, 4, false);
  fb_->bind_draw();
  glClearColor(r, g, b, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  return imgui_.begin(width, height);
}

Image Canvas::end() {
  imgui_.end();
  Image out;
  fb_->resolve_and_read(out);
  imgui_.clear_textures();
  return out;
}

}  // namespace render
