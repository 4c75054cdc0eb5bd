#include "app/simulation/tool_depth.hpp"

#include <cmath>

#include "engine/geometry.hpp"

namespace vdmsim {

double depth_inside(const vdm::NodeMat& x, const vdm::TriMat& triangles, const vdm::Vec3& p) {
  // The generalised winding number: the solid angles of the triangles seen from p (Van
  // Oosterom and Strackee's formula), over 4 pi.
  double solid = 0;
  for (Eigen::Index k = 0; k < triangles.rows(); ++k) {
    const vdm::Vec3 a = x.row(triangles(k, 0)).transpose() - p, b = x.row(triangles(k, 1)).transpose() - p,
                    c = x.row(triangles(k, 2)).transpose() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double det = a.dot(b.cross(c));
    const double div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    solid += 2 * std::atan2(det, div);
  }
  if (solid / (4 * M_PI) < 0.5) return 0;
  double nearest = INFINITY;
  for (Eigen::Index k = 0; k < triangles.rows(); ++k) {
    const vdm::Vec3 a = x.row(triangles(k, 0)), b = x.row(triangles(k, 1)), c = x.row(triangles(k, 2));
    const vdm::Vec3 w = vdm::closest_barycentric(p, a, b, c);
    nearest = std::min(nearest, (w[0] * a + w[1] * b + w[2] * c - p).norm());
  }
  return nearest;
}

bool deeper_inside(const vdm::NodeMat& x, const vdm::TriMat& triangles, const vdm::Vec3& p, double limit) {
  const double limit2 = limit * limit;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if ((x.row(i).transpose() - p).squaredNorm() <= limit2) return false;
  return depth_inside(x, triangles, p) > limit;
}

}  // namespace vdmsim
