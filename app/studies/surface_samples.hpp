#pragma once
// A fixed set of points on an organ's surface, located on a particular mesh of it: each
// point is tied to its closest point on the rest surface (a triangle and barycentric weights),
// so that displacement fields of meshes of different resolution (or of different models on
// the same mesh) can be compared at the same material points.
#include <array>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim {

class SurfaceSamples {
 public:
  // Ties every row of `points` (metres, near the surface) to `rest`'s closest surface point,
  // searched among the triangles around the nearest nodes.
  SurfaceSamples(const vdm::SurfaceMesh& rest, const vdm::NodeMat& points);

  int size() const { return static_cast<int>(tri_.size()); }
  // Displacements at the samples (size() x 3) from per-node displacements u of the mesh.
  void interpolate(const vdm::NodeMat& u, vdm::NodeMat& out) const;
  // Largest distance from a point to its tied surface point (m): how well the meshes agree.
  double max_gap() const { return max_gap_; }

 private:
  std::vector<std::array<int, 3>> tri_;   // nodes of the tied triangle
  std::vector<vdm::Vec3> weight_;         // barycentric weights
  double max_gap_ = 0;
};


}  // namespace vdmsim
