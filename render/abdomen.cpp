#include "render/abdomen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/camera.hpp"

namespace render {

Abdomen abdomen_around(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const std::vector<Eigen::Vector3d>& ports) {
  Abdomen a;
  a.centre = 0.5 * (lo + hi);
  double nearest_port = 0;
  if (!ports.empty()) {
    nearest_port = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : ports) nearest_port = std::min(nearest_port, (p - a.centre).norm());
  }
  a.radius = std::max(1.35 * 0.5 * (hi - lo).norm(), nearest_port);
  a.radius = std::max(a.radius, 1e-6);
  return a;
}

SkinMesh abdomen_wall(const Abdomen& a, int rings) {
  SkinMesh m;
  const int segments = 2 * rings;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i <= rings; ++i) {
    const double theta = pi * i / rings;  // from the top (+z) down
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * pi * j / segments;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      m.positions.push_back((a.centre + a.radius * d).cast<float>());
      m.normals.push_back((-d).cast<float>());
    }
  }
  // Wound counter-clockwise as seen from inside (the front faces are the inner ones).
  const unsigned row = unsigned(segments + 1);
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const unsigned p = unsigned(i) * row + unsigned(j), q = p + row;
      m.indices.insert(m.indices.end(), {p, p + 1, q, p + 1, q + 1, q});
    }
  return m;
}

Camera endoscope_camera(const Eigen::Isometry3d& pose, double vertical_fov_deg) {
  Camera c;
  c.eye = pose.translation();
  c.target = c.eye + pose.linear().col(2);
  c.up = -pose.linear().col(1);
  c.fov_deg = vertical_fov_deg;
  return c;
}

}  // namespace render
