#pragma once
// A probe as a capsule: the segment p0-p1 swept by a sphere. The tests and the Bullet
// benchmark describe probes this way; contact takes it as the capsule tool shape it is.
#include "engine/tool_shape.hpp"
#include "engine/types.hpp"

namespace vdm {

// A capsule: the segment p0-p1 swept by a sphere of `radius` (m). A probe is one.
struct Capsule {
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::UnitZ();  // p0: centre of the tip's rounded end
  double radius = 0.004;
  Vec3 motion = Vec3::Zero();  // how far it moved since the last step (m): the push direction
};

// A capsule as a tool shape.
ToolShape to_tool(const Capsule& c);

// Signed distance from x to the capsule's surface (negative inside), the closest surface
// point and the outward normal there.
double capsule_distance(const Capsule& c, const Vec3& x, Vec3& surface_point, Vec3& normal);

}  // namespace vdm
