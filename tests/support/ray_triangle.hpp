#pragma once
// The ray-triangle intersection the ray-cast tests measure pictures against.
#include <Eigen/Core>
#include <cmath>
#include <limits>

namespace test {

// Moller-Trumbore: the parameter t > 0 at which the ray o + t d meets triangle (a, b, c), or
// +infinity when it does not.
inline double ray_triangle(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  constexpr double kMissed = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-20) return kMissed;
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return kMissed;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return kMissed;
  const double t = e2.dot(q) / det;
  return t > 0 ? t : kMissed;
}

}  // namespace test
