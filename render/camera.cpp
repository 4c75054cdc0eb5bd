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

// look_at's up: an up parallel to the view direction has no side, and another up is taken.
Eigen::Vector3d usable_up(const Eigen::Vector3d& forward, const Eigen::Vector3d& up) {
  if (forward.cross(up).norm() >= 1e-9) return up;
  return std::abs(forward.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
}

}  // namespace

Eigen::Isometry3d camera_pose(const Camera& c) {
  // glm::lookAtRH's axes: f forward, s = f x up to the right, u = s x f up; OpenCV's y is down.
  const Eigen::Vector3d f = (c.target - c.eye).normalized();
  const Eigen::Vector3d s = f.cross(usable_up(f, c.up)).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = s;
  pose.linear().col(1) = -u;
  pose.linear().col(2) = f;
  pose.translation() = c.eye;
  return pose;
}

CameraModel camera_model(const Camera& c, int width, int height, double near, double far) {
  // OpenGL maps a pixel's centre to window coordinates (i + 1/2, j + 1/2) with rows from the
  // bottom; the vertical field of view spans the image's height, square pixels.
  CameraModel m;
  m.width = width;
  m.height = height;
  m.fy = 0.5 * height / std::tan(0.5 * c.fov_deg * M_PI / 180.0);
  m.fx = m.fy;
  m.cx = 0.5 * (width - 1);
  m.cy = 0.5 * (height - 1);
  m.near = near;
  m.far = far;
  m.pose = camera_pose(c);
  return m;
}

// The camera maths in GLM's GLSL-shaped types (right-handed, clip depth -1 to 1: OpenGL's).
Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  return to_eigen(glm::lookAtRH(to_glm(eye), to_glm(target), to_glm(usable_up((target - eye).normalized(), up))));
}

Eigen::Matrix4f perspective(double fov_deg, double aspect, double n, double f) {
  return to_eigen(glm::perspectiveRH_NO(glm::radians(fov_deg), aspect, n, f));
}

Eigen::Matrix4f orthographic(double l, double r, double b, double t, double n, double f) {
  return to_eigen(glm::orthoRH_NO(l, r, b, t, n, f));
}

}  // namespace render
