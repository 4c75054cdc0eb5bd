#pragma once
// The convex hull of a point set (an instrument's collision shape from a mesh): vertices,
// outward triangles and face planes. Built once when a scene is prepared, never per step.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

struct ConvexHull {
  std::vector<Vec3> vertices;                 // hull vertices (m)
  std::vector<std::array<int, 3>> triangles;  // outward (counter-clockwise seen from outside)
  std::vector<Vec3> normals;                  // unit outward normal per triangle
  std::vector<double> offsets;                // plane of triangle k: normals[k] . x = offsets[k]
  Vec3 centroid = Vec3::Zero();               // mean of the vertices (inside the hull)
  double inradius = 0;                        // distance from the centroid to the nearest face (m)
  double bound = 0;                           // largest distance from the origin to a vertex (m)
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // axis-aligned bounds of the vertices (m)
};

// The most points a hull is built from: the build is O(n f) (f: the hull's faces, up to 2n)
// and each contact query O(f); a mesh with more vertices is to be simplified first.
constexpr std::size_t kMaxHullPoints = 10000;

// Builds the hull of `points` (incremental, O(n f)). False with a message when the points
// span no volume (fewer than four, or all on one plane, relative to their extent), or when
// they are more than kMaxHullPoints.
bool convex_hull(const std::vector<Vec3>& points, ConvexHull& out, std::string& error);

// Signed distance from x to the hull's surface (negative inside), the closest surface point
// and the outward normal there. Exact: inside, the nearest face plane; outside, the nearest
// point of the hull's triangles.
double convex_hull_distance(const ConvexHull& h, const Vec3& x, Vec3& surface_point, Vec3& normal);

}  // namespace vdm
