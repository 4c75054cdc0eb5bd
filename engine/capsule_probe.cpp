#include "engine/capsule_probe.hpp"

#include <algorithm>

namespace vdm {

double capsule_distance(const Capsule& c, const Vec3& x, Vec3& surface_point, Vec3& normal) {
  const Vec3 d = c.p1 - c.p0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((x - c.p0).dot(d) / len2, 0.0, 1.0) : 0.0;
  const Vec3 axis_point = c.p0 + t * d;
  Vec3 r = x - axis_point;
  double dist = r.norm();
  if (dist < 1e-15) {  // on the axis: any direction perpendicular to it
    r = d.unitOrthogonal();
    dist = 0.0;
  } else {
    r /= dist;
  }
  normal = r;
  surface_point = axis_point + c.radius * r;
  return dist - c.radius;
}

ToolShape to_tool(const Capsule& c) { return capsule_shape(c.p0, c.p1, c.radius, c.motion); }

}  // namespace vdm
