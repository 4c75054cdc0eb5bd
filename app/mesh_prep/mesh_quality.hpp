#pragma once
// The numbers by which a prepared organ surface is judged: nodes, volume, area, smallest
// triangle angle, bounding box (no CGAL).
#include "engine/types.hpp"

namespace vdmsim {

struct MeshQuality {
  int nodes = 0, triangles = 0;
  double volume = 0;                // enclosed, by the triangles' orientation (outward: positive)
  double area = 0;
  double smallest_angle_deg = 0;    // over every triangle's three angles
  double mean_edge = 0;
  vdm::Vec3 lo = vdm::Vec3::Zero(), hi = vdm::Vec3::Zero();
};

MeshQuality measure_mesh(const vdm::SurfaceMesh& mesh);

// The smallest of the triangle's three angles, in degrees (0 for a degenerate one).
double smallest_angle_deg(const vdm::Vec3& a, const vdm::Vec3& b, const vdm::Vec3& c);

}  // namespace vdmsim
