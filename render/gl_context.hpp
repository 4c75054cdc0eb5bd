#pragma once
// An offscreen OpenGL 4.5 core context through OSMesa (llvmpipe: no display, no GPU).
// Drawing goes to framebuffer objects (see Framebuffer); OSMesa's own buffer is only what
// the context is made current on.
#include <memory>
#include <string>
#include <vector>

namespace render {

struct Image;

class GlContext {
 public:
  // Creates a context and makes it current on this thread. nullptr with `error` on failure.
  static std::unique_ptr<GlContext> create(std::string& error);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;
  // Makes the context current again (after another context was used on this thread).
  bool make_current();
  std::string renderer_name() const;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  GlContext() = default;
  void* context_ = nullptr;  // OSMesaContext
  std::vector<unsigned char> buffer_;
};

// An RGBA8 framebuffer with depth, multisampled (`samples` > 1) and resolved into a
// single-sample colour buffer that is read back into an Image (single-sample: read directly).
class Framebuffer {
 public:
  // `depth`: with a depth buffer (2D drawing such as a Canvas needs none).
  Framebuffer(int width, int height, int samples, bool depth = true);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;
  bool ok() const { return ok_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return samples_; }
  void bind_draw();                        // the multisampled target, viewport set
  void resolve_and_read(Image& out);      // rows top first
  // Copies the colour of the framebuffer object `fbo` (same size and samples) into this
  // one's multisampled target, or this one's into `fbo`.
  void copy_color_from(unsigned fbo);
  void blit_color_to(unsigned fbo);

 private:
  int width_, height_, samples_;
  unsigned draw_fbo_ = 0, draw_color_ = 0, draw_depth_ = 0;
  unsigned read_fbo_ = 0, read_color_ = 0;
  bool ok_ = false;
};

}  // namespace render
