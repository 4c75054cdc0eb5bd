#pragma once
// How far one surface lies from another: points sampled evenly over `from` (by area), each
// point's distance to the nearest point of `to` (CGAL's AABB tree), their mean and maximum.
#include "engine/types.hpp"

namespace vdmsim {

struct SurfaceDistance {
  double mean = 0, max = 0;
  int samples = 0;
};

// About `samples` points (at least one per triangle, at its centroid, and every node).
SurfaceDistance sampled_distance(const vdm::SurfaceMesh& from, const vdm::SurfaceMesh& to, int samples = 200000);

}  // namespace vdmsim
