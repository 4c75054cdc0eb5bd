#include "render/gl_context.hpp"

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include "render/image.hpp"

namespace render {

std::unique_ptr<GlContext> GlContext::create(std::string& error) {
  const int attribs[] = {OSMESA_FORMAT,          OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,      24,
                         OSMESA_PROFILE,         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION, 4,
                         OSMESA_CONTEXT_MINOR_VERSION, 5,
                         0};
  std::unique_ptr<GlContext> ctx(new GlContext());
  ctx->context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx->context_) {
    error = "OSMesa could not create an OpenGL 4.5 core context (is libosmesa6 installed?)";
    return nullptr;
  }
  ctx->buffer_.assign(16 * 16 * 4, 0);
  if (!ctx->make_current()) {
    error = "OSMesaMakeCurrent failed";
    return nullptr;
  }
  return ctx;
}

GlContext::~GlContext() {
  if (context_) OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

bool GlContext::make_current() {
  return OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), buffer_.data(), GL_UNSIGNED_BYTE, 16, 16) == GL_TRUE;
}

std::string GlContext::renderer_name() const {
  const GLubyte* s = glGetString(GL_RENDERER);
  return s ? reinterpret_cast<const char*>(s) : "unknown";
}

Framebuffer::Framebuffer(int width, int height, int samples, bool depth)
    : width_(width), height_(height), samples_(samples) {
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (samples_ > max_samples) samples_ = max_samples;
  if (samples_ < 1) samples_ = 1;
  glGenFramebuffers(1, &draw_fbo_);
  glGenRenderbuffers(1, &draw_color_);
  glBindRenderbuffer(GL_RENDERBUFFER, draw_color_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0, GL_RGBA8, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, draw_color_);
  if (depth) {
    glGenRenderbuffers(1, &draw_depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, draw_depth_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_ > 1 ? samples_ : 0, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, draw_depth_);
  }
  ok_ = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;

  if (samples_ > 1) {  // the resolve target (a single-sample buffer is read directly)
    glGenFramebuffers(1, &read_fbo_);
    glGenRenderbuffers(1, &read_color_);
    glBindRenderbuffer(GL_RENDERBUFFER, read_color_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, read_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, read_color_);
    ok_ = ok_ && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Framebuffer::~Framebuffer() {
  glDeleteFramebuffers(1, &draw_fbo_);
  glDeleteFramebuffers(1, &read_fbo_);
  glDeleteRenderbuffers(1, &draw_color_);
  glDeleteRenderbuffers(1, &draw_depth_);
  glDeleteRenderbuffers(1, &read_color_);
}

void Framebuffer::bind_draw() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glViewport(0, 0, width_, height_);
}

void Framebuffer::copy_color_from(unsigned fbo) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, draw_fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

void Framebuffer::blit_color_to(unsigned fbo) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

void Framebuffer::resolve_and_read(Image& out) {
  if (samples_ > 1) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, read_fbo_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo_);
  } else {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);  // single-sample: read it directly
  }
  if (out.width != width_ || out.height != height_) out = Image(width_, height_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  flip_rows(out);
}

}  // namespace render
