#pragma once
// vdmsim locate: where a ray first meets an organ surface, and the surface's outward normal
// there (to place an instrument on the organ).
#include <ostream>
#include <string>

#include "engine/types.hpp"

namespace vdmsim {

struct RayHit {
  bool hit = false;
  vdm::Vec3 point = vdm::Vec3::Zero();
  vdm::Vec3 normal = vdm::Vec3::Zero();  // the hit triangle's unit normal, as the surface is oriented
  int triangle = -1;
  double distance = 0;                   // from the ray's origin, along the unit direction
};

// The first crossing of the ray from `from` along `direction` (any length, not zero) with the
// triangles of `mesh` (Moller-Trumbore on every triangle: one query, linear time).
RayHit first_hit(const vdm::SurfaceMesh& mesh, const vdm::Vec3& from, const vdm::Vec3& direction);

// The command: loads MESH (validated, oriented outward, scaled), prints `point: X Y Z` and
// `normal: NX NY NZ` in metres; exit 2 when the ray misses or the input is bad.
int cmd_locate(const std::string& mesh_path, double scale, const vdm::Vec3& from, const vdm::Vec3& toward,
               std::ostream& out, std::ostream& err);

}  // namespace vdmsim
