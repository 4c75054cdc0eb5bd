#pragma once
// Where a surface point found inside a tool goes: back along its motion relative to the tool,
// to the tool's surface. Kinematic contact holds nodes there; constraint contact measures
// the gap of a point deep inside a fast tool to there.
#include "engine/capsule_probe.hpp"
#include "engine/tool_shape.hpp"
#include "engine/types.hpp"

namespace vdm {

// Where a node inside the capsule is pushed: back along its motion relative to the capsule,
// `relative` (the node's displacement minus the capsule's; when zero, along the axis toward
// the tip), to the capsule's surface. A node the probe runs into is pushed ahead of it
// instead of sliding round its tip; a surface springing back into a retreating probe is
// caught by the tip. On return `direction` is the push direction.
Vec3 push_out(const Capsule& c, const Vec3& x, const Vec3& relative, Vec3& direction);
// The same for any tool shape (`relative`: the node's displacement minus the tool's there;
// when zero, along the shape's +z: toward its tip).
Vec3 push_out(const ToolShape& t, const Vec3& x, const Vec3& relative, Vec3& direction);

}  // namespace vdm
