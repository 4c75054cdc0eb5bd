#include "engine/push_out.hpp"

#include <algorithm>

namespace vdm {

Vec3 push_out(const ToolShape& t, const Vec3& x, const Vec3& relative, Vec3& dir) {
  const double m = relative.norm(), size = t.size();
  dir = m > 1e-9 * size ? Vec3(-relative / m) : Vec3(t.pose.linear().col(2));
  Vec3 nearest, nearest_normal, p, nrm;
  if (tool_distance(t, x, nearest, nearest_normal) >= 0.0) return x;
  // Along a ray from inside, the distance to a convex surface crosses zero once. The
  // bisection needs only the sign: for a capsule (the probe) it is taken with the pose's
  // inverse made once per ray and without the surface point and normal, the same operations
  // as tool_distance's on the way to the distance, so the same bits.
  const bool capsule = t.kind == ToolShape::Kind::capsule;
  const Eigen::Isometry3d to_shape = t.pose.inverse();
  auto inside = [&](const Vec3& y) {
    if (!capsule) return tool_distance(t, y, p, nrm) < 0.0;
    const Vec3 q = to_shape * y;
    const double h = t.half_size.z();
    const Vec3 r = q - Vec3(0, 0, std::clamp(q.z(), -h, h));
    return r.norm() - t.rounding < 0.0;
  };
  double lo = 0.0, hi = 2.0 * t.bound() + 2.0 * size;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (inside(x + mid * dir) ? lo : hi) = mid;
  }
  // A node that came in from behind (the surface springing back into a retreating tool)
  // would exit far away along the motion: put it on the nearest surface point instead.
  if (hi > 2.0 * size + m) {
    dir = nearest_normal;
    return nearest;
  }
  return x + hi * dir;
}

Vec3 push_out(const Capsule& c, const Vec3& x, const Vec3& relative, Vec3& dir) {
  return push_out(to_tool(c), x, relative, dir);
}

}  // namespace vdm
