#include "render/camera.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace render {

Camera auto_frame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double fov_deg, double aspect) {
  Camera c;
  c.fov_deg = fov_deg;
  c.target = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-6);
  const double half_v = 0.5 * fov_deg * M_PI / 180.0;
  const double half_h = std::atan(std::tan(half_v) * aspect);
  const double half = std::min(half_v, half_h);
  const double distance = 1.02 * radius / std::sin(half);
  const Eigen::Vector3d dir = Eigen::Vector3d(0.35, -1.0, 0.75).normalized();
  c.eye = c.target + distance * dir;
  c.up = Eigen::Vector3d::UnitZ();
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
