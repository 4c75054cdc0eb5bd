#pragma once
// The enclosed volume and its rate of change along a move of the surface, in one pass over
// the triangles: what the step's volume correction (Newton on V along the fluid's response)
// needs at each iterate, without forming the area vectors.
#include <vector>

#include "engine/types.hpp"

namespace vdm {

struct VolumeAlong {
  double volume = 0;  // enclosed_volume(x, tris, origin), bit for bit (m^3)
  double slope = 0;   // dV/dt of x + t d at t = 0: A(x) . d (m^3 per unit of t)
};

// For a closed, outward surface (triangles `tris`) at positions x and a move d. Entries of d
// where `frozen` is not 0 are taken as 0 (frozen may be null). `packed` (6 N doubles once
// sized: no allocation after the first call) holds each node's position and move together.
VolumeAlong volume_along(const NodeMat& x, const NodeMat& d, const FlagMat* frozen, const TriMat& tris,
                         const Vec3& origin, std::vector<double>& packed);

}  // namespace vdm
