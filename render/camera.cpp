#include "render/camera.hpp"

#include <Eigen/Geometry>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <algorithm>
#include <cmath>

namespace render {

Camera auto_frame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double fov_deg, double aspect) {
  Camera c;
  c.fov_deg = fov_deg;
  c.target = 0.5 * (lo + hi);
  c.up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d dir = Eigen::Vector3d(0.35, -1.0, 0.75).normalized();  // target -> eye
  // Camera axes, then the distance at which every corner of the box fits the view with a 6 %
  // margin on each side.
  const Eigen::Vector3d forward = -dir, side = forward.cross(c.up).normalized(), up = side.cross(forward);
  const double tan_v = std::tan(0.5 * fov_deg * M_PI / 180.0) * 0.88, tan_h = tan_v * aspect;
  double distance = 1e-6;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
    const Eigen::Vector3d r = corner - c.target;
    const double depth = r.dot(dir);  // toward the eye
    distance = std::max({distance, depth + std::abs(r.dot(side)) / tan_h, depth + std::abs(r.dot(up)) / tan_v});
  }
  c.eye = c.target + distance * dir;
  return c;
}

namespace {

glm::dvec3 to_glm(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// GLM's column-major matrix as the renderer's Eigen one (also column-major), in floats for GL.
Eigen::Matrix4f to_eigen(const glm::dmat4& m) {
  Eigen::Matrix4f out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out(r, c) = static_cast<float>(m[c][r]);
  return out;
}

}  // namespace

// The camera maths in GLM's GLSL-shaped types (right-handed, clip depth -1 to 1: OpenGL's).
Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  // An up parallel to the view direction has no side: another up is taken.
  const Eigen::Vector3d f = (target - eye).normalized();
  Eigen::Vector3d u = up;
  if (f.cross(up).norm() < 1e-9) u = std::abs(f.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  return to_eigen(glm::lookAtRH(to_glm(eye), to_glm(target), to_glm(u)));
}

Eigen::Matrix4f perspective(double fov_deg, double aspect, double n, double f) {
  return to_eigen(glm::perspectiveRH_NO(glm::radians(fov_deg), aspect, n, f));
}

Eigen::Matrix4f orthographic(double l, double r, double b, double t, double n, double f) {
  return to_eigen(glm::orthoRH_NO(l, r, b, t, n, f));
}

}  // namespace render
