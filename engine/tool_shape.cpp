#include "engine/tool_shape.hpp"

#include <algorithm>
#include <cmath>

#include "engine/rotation.hpp"

namespace vdm {
namespace {

// On the axis any direction across it will do: the one Eigen picks across the world axis
// from the tip toward the handle (as capsule_distance does), in the shape frame.
Vec3 across_axis(const ToolShape& t) {
  return t.pose.linear().transpose() * Vec3(-t.pose.linear().col(2)).unitOrthogonal();
}

// Signed distance to the core (in the shape frame), closest core surface point, outward normal.
double core_distance(const ToolShape& t, const Vec3& p, Vec3& cp, Vec3& n) {
  const double e = t.rounding;
  switch (t.kind) {
    case ToolShape::Kind::capsule: {
      const double h = t.half_size.z();
      cp = Vec3(0, 0, std::clamp(p.z(), -h, h));
      Vec3 r = p - cp;
      const double d = r.norm();
      n = d > 1e-15 ? Vec3(r / d) : across_axis(t);
      return d;
    }
    case ToolShape::Kind::cylinder: {
      const double rc = std::max(t.half_size.x() - e, 0.0), hc = std::max(t.half_size.z() - e, 0.0);
      const double rho = std::hypot(p.x(), p.y());
      const Vec3 radial = rho > 1e-15 ? Vec3(p.x() / rho, p.y() / rho, 0) : across_axis(t);
      const double qx = rho - rc, qz = std::abs(p.z()) - hc;
      const double sz = p.z() >= 0 ? 1.0 : -1.0;
      if (qx <= 0 && qz <= 0) {  // inside: the nearer of the side and the end cap
        if (qx > qz) {
          n = radial;
          cp = Vec3(rc * radial.x(), rc * radial.y(), p.z());
          return qx;
        }
        n = Vec3(0, 0, sz);
        cp = Vec3(p.x(), p.y(), sz * hc);
        return qz;
      }
      const double rr = std::min(rho, rc);
      cp = Vec3(rr * radial.x(), rr * radial.y(), std::clamp(p.z(), -hc, hc));
      const Vec3 r = p - cp;
      const double d = r.norm();
      n = d > 1e-15 ? Vec3(r / d) : (qx > qz ? radial : Vec3(0, 0, sz));
      return d;
    }
    case ToolShape::Kind::box: {
      const Vec3 b = (t.half_size.array() - e).max(0.0).matrix();
      const Vec3 q = p.cwiseAbs() - b;
      if (q.maxCoeff() <= 0) {  // inside: the nearest face
        int a = 0;
        q.maxCoeff(&a);
        n = Vec3::Zero();
        n[a] = p[a] >= 0 ? 1.0 : -1.0;
        cp = p;
        cp[a] = n[a] * b[a];
        return q[a];
      }
      cp = p.cwiseMax(-b).cwiseMin(b);
      const Vec3 r = p - cp;
      const double d = r.norm();
      n = r / d;
      return d;
    }
    case ToolShape::Kind::convex:
      return convex_hull_distance(*t.hull, p, cp, n);
  }
  return 0;
}

}  // namespace

double ToolShape::size() const {
  switch (kind) {
    case Kind::capsule: return rounding;
    case Kind::cylinder: return std::min(half_size.x(), half_size.z());
    case Kind::box: return half_size.minCoeff();
    case Kind::convex: return hull ? hull->inradius + rounding : rounding;
  }
  return rounding;
}

double ToolShape::bound() const {
  switch (kind) {
    case Kind::capsule: return half_size.z() + rounding;
    case Kind::cylinder: return std::hypot(half_size.x(), half_size.z());
    case Kind::box: return half_size.norm();
    case Kind::convex: return (hull ? hull->bound : 0.0) + rounding;
  }
  return 0;
}

double tool_distance(const ToolShape& t, const Vec3& x, Vec3& surface_point, Vec3& normal) {
  const Vec3 p = t.pose.inverse() * x;
  Vec3 cp = Vec3::Zero(), n = Vec3::UnitZ();
  const double d = core_distance(t, p, cp, n) - t.rounding;
  normal = t.pose.linear() * n;
  surface_point = t.pose * Vec3(cp + t.rounding * n);
  return d;
}

ToolShape capsule_shape(const Vec3& p0, const Vec3& p1, double radius, const Vec3& motion) {
  ToolShape t;
  t.kind = ToolShape::Kind::capsule;
  const Vec3 d = p0 - p1;  // toward the tip
  const double len = d.norm();
  t.pose.linear() = rotation_between(Vec3::UnitZ(), len > 0 ? Vec3(d / len) : Vec3::UnitZ()).toRotationMatrix();
  t.pose.translation() = 0.5 * (p0 + p1);
  t.half_size = Vec3(radius, radius, 0.5 * len);
  t.rounding = radius;
  t.previous = t.pose;
  t.previous.pretranslate(-motion);
  return t;
}

}  // namespace vdm
