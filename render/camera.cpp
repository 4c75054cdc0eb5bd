#include "render/camera.hpp"

#include <Eigen/Geometry>
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

Eigen::Matrix4f look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d f = (target - eye).normalized();
  Eigen::Vector3d s = f.cross(up);
  if (s.norm() < 1e-9) s = f.cross(std::abs(f.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY());
  s.normalize();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m.cast<float>();
}

Eigen::Matrix4f perspective(double fov_deg, double aspect, double n, double f) {
  const double t = 1.0 / std::tan(0.5 * fov_deg * M_PI / 180.0);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (f + n) / (n - f);
  m(2, 3) = 2 * f * n / (n - f);
  m(3, 2) = -1;
  return m.cast<float>();
}

Eigen::Matrix4f orthographic(double l, double r, double b, double t, double n, double f) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2 / (r - l);
  m(1, 1) = 2 / (t - b);
  m(2, 2) = -2 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m.cast<float>();
}

}  // namespace render
