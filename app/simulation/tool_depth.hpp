#pragma once
// How deep a point is inside an organ's closed surface (its current positions): for the run's
// guard against an instrument far inside the organ, which contact could not push away (a
// rigid material, nodes held in place) while the run reported no force.
#include "engine/types.hpp"

namespace vdmsim {

// The distance from `p` to the surface when `p` is inside it (its winding number over the
// outward triangles is about 1), else 0. O(triangles).
double depth_inside(const vdm::NodeMat& x, const vdm::TriMat& triangles, const vdm::Vec3& p);

// depth_inside(x, triangles, p) > limit, without the triangles when some node is within
// `limit` of p (the surface is then no farther): the run's per-frame guard, O(nodes) while
// an instrument touches the organ.
bool deeper_inside(const vdm::NodeMat& x, const vdm::TriMat& triangles, const vdm::Vec3& p, double limit);

}  // namespace vdmsim
