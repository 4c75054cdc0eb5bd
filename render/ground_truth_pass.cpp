#include "render/ground_truth_pass.hpp"

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "render/shaders.hpp"

namespace render {

GroundTruthPass::~GroundTruthPass() {
  glDeleteFramebuffers(1, &fbo_);
  const GLuint buffers[4] = {ids_, normals_, camera_z_, depth_};
  glDeleteRenderbuffers(4, buffers);
}

bool GroundTruthPass::init(int width, int height, std::string& error) {
  width_ = width;
  height_ = height;
  if (!program_.build(shaders::kGroundTruthVertex, shaders::kGroundTruthFragment, error)) return false;
  u_id_ = program_.uniform("u_id");
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  auto attach = [&](GLuint& buffer, GLenum format, GLenum attachment) {
    glGenRenderbuffers(1, &buffer);
    glBindRenderbuffer(GL_RENDERBUFFER, buffer);
    glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
  };
  attach(ids_, GL_R8UI, GL_COLOR_ATTACHMENT0);
  attach(normals_, GL_RGBA8, GL_COLOR_ATTACHMENT1);
  attach(camera_z_, GL_R32F, GL_COLOR_ATTACHMENT2);
  attach(depth_, GL_DEPTH_COMPONENT24, GL_DEPTH_ATTACHMENT);
  const GLenum targets[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glDrawBuffers(3, targets);
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!complete) {
    error = "OpenGL ground-truth framebuffer incomplete at " + std::to_string(width) + "x" + std::to_string(height);
    return false;
  }
  return true;
}

GlProgram& GroundTruthPass::begin(const Eigen::Matrix4f& view_proj, const Eigen::Matrix4f& view) {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width_, height_);
  glDisable(GL_BLEND);  // (nothing else enables it: the ImGui overlay restores what it changes)
  const GLuint no_id[4] = {0, 0, 0, 0};
  const GLfloat black[4] = {0, 0, 0, 0}, no_z[4] = {0, 0, 0, 0}, far_depth = 1.0f;
  glClearBufferuiv(GL_COLOR, 0, no_id);
  glClearBufferfv(GL_COLOR, 1, black);
  glClearBufferfv(GL_COLOR, 2, no_z);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glUseProgram(program_.id());
  glUniformMatrix4fv(program_.uniform("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniformMatrix4fv(program_.uniform("u_view"), 1, GL_FALSE, view.data());
  return program_;
}

void GroundTruthPass::set_id(unsigned id) { glUniform1ui(u_id_, id); }

namespace {

// Reverses the row order of a w x h array of `T` (OpenGL reads bottom-up).
template <typename T>
void flip_ground_truth_rows(std::vector<T>& values, size_t row_length, int height) {
  for (int y = 0; y < height / 2; ++y)
    std::swap_ranges(values.begin() + std::ptrdiff_t(size_t(y) * row_length),
                     values.begin() + std::ptrdiff_t(size_t(y + 1) * row_length),
                     values.begin() + std::ptrdiff_t(size_t(height - 1 - y) * row_length));
}

}  // namespace

void GroundTruthPass::read_ids(Image& out) {
  std::vector<std::uint8_t> ids(size_t(width_) * size_t(height_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_BYTE, ids.data());
  flip_ground_truth_rows(ids, size_t(width_), height_);
  if (out.width != width_ || out.height != height_) out = Image(width_, height_);
  for (size_t i = 0; i < ids.size(); ++i) {
    std::uint8_t* p = &out.rgba[i * 4];
    p[0] = p[1] = p[2] = ids[i];
    p[3] = 255;
  }
}

void GroundTruthPass::read_normals(Image& out) {
  if (out.width != width_ || out.height != height_) out = Image(width_, height_);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.rgba.data());
  flip_rows(out);
}

void GroundTruthPass::read_camera_z(FloatImage& out) {
  out.width = width_;
  out.height = height_;
  out.values.resize(size_t(width_) * size_t(height_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT2);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width_, height_, GL_RED, GL_FLOAT, out.values.data());
  flip_ground_truth_rows(out.values, size_t(width_), height_);
}

}  // namespace render
