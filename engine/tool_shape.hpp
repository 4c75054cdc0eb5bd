#pragma once
// A rigid instrument's collision shape for contact: an FCL primitive (capsule, cylinder, box)
// or a convex polytope, placed in the world by a pose. Every shape is a convex core swept by
// a sphere of `rounding` (a capsule: a segment swept by its radius; a cylinder with a
// rounded tip: a thinner, shorter cylinder swept by the tip's rounding radius), so its signed
// distance is the core's minus the rounding, exactly.
#include <memory>

#include <Eigen/Geometry>

#include "engine/convex_hull.hpp"
#include "engine/types.hpp"

namespace vdm {

struct ToolShape {
  enum class Kind { capsule, cylinder, box, convex } kind = Kind::capsule;
  // Shape frame -> world. Shapes are centred at their frame's origin with their axis along z
  // (FCL's convention); a convex hull is given in its own frame as it is.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // Outer half sizes (m): capsule (radius, radius, half the segment's length: the capsule
  // reaches half_size.z + radius); cylinder (radius, radius, half length); box (x, y, z).
  Vec3 half_size = Vec3(0.004, 0.004, 0.1);
  double rounding = 0;  // capsule: its radius; cylinder, box: edge rounding (m), 0 = sharp
  std::shared_ptr<const ConvexHull> hull;  // convex only
  // The pose one step earlier: a node the tool runs into is pushed back along their
  // relative motion.
  Eigen::Isometry3d previous = Eigen::Isometry3d::Identity();

  // Smallest half width (m): the unit of the contact tolerances (2 % of it, sub-steps).
  double size() const;
  // Radius of a sphere about the frame's origin that holds the shape (m).
  double bound() const;
  // The tool's own displacement over the last step at world point x (m).
  Vec3 motion_at(const Vec3& x) const { return x - previous * (pose.inverse() * x); }
};

// Signed distance from world point x to the shape's surface (negative inside), the closest
// surface point and the outward normal there.
double tool_distance(const ToolShape& t, const Vec3& x, Vec3& surface_point, Vec3& normal);

// A capsule from its segment p0 (centre of the tip's rounded end) - p1 and radius, moved by
// `motion` since the last step.
ToolShape capsule_shape(const Vec3& p0, const Vec3& p1, double radius, const Vec3& motion = Vec3::Zero());

}  // namespace vdm
