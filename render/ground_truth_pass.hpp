#pragma once
// The ground-truth views' pass (render/views.hpp: ViewPass::ground_truth): the scene's objects
// drawn once, one sample per pixel with no blending, into three targets at once: each
// object's id (8-bit unsigned integer), its normal in camera axes (RGBA8) and its camera z
// (float32), with a depth buffer of its own. The caller binds the program begin() returns,
// draws each object after set_id(), then reads the targets back.
#include <Eigen/Core>
#include <string>

#include "render/gl_program.hpp"
#include "render/image.hpp"
#include "render/view_image.hpp"

namespace render {

class GroundTruthPass {
 public:
  GroundTruthPass() = default;
  ~GroundTruthPass();  // with the GL context current
  GroundTruthPass(const GroundTruthPass&) = delete;
  GroundTruthPass& operator=(const GroundTruthPass&) = delete;

  // The targets at width x height and the program. False with `error`.
  bool init(int width, int height, std::string& error);
  // Binds and clears the targets (id 0, normal black, camera z 0, depth the far plane) and
  // returns the program with the camera's matrices set (`view`: world to OpenGL's camera
  // space, `view_proj`: the projection after it).
  GlProgram& begin(const Eigen::Matrix4f& view_proj, const Eigen::Matrix4f& view);
  void set_id(unsigned id);
  // The targets, rows top first: ids as grey (every colour channel the id, alpha 255),
  // normals as RGB (n + 1) / 2 (black where no surface), camera z in metres (0 where none).
  void read_ids(Image& out);
  void read_normals(Image& out);
  void read_camera_z(FloatImage& out);

 private:
  int width_ = 0, height_ = 0;
  unsigned fbo_ = 0, ids_ = 0, normals_ = 0, camera_z_ = 0, depth_ = 0;
  GlProgram program_;
  int u_id_ = -1;
};

}  // namespace render
