#pragma once
// The project's own liver-like organ: a smooth implicit two-lobe shape (a thick right lobe
// and a thin left lobe blended together), meshed by projecting a subdivided icosahedron onto
// it and relaxing the nodes along the surface. Level 4, 5, 6 give 2562, 10242, 40962 nodes.
#include "engine/types.hpp"

namespace vdmsim {

struct LiverShape {
  // Implicit function: < 0 inside, 0 on the surface, > 0 outside (dimensionless).
  double value(const vdm::Vec3& p) const;
  vdm::Vec3 gradient(const vdm::Vec3& p) const;
  vdm::Vec3 center() const { return vdm::Vec3(0.0, 0.0, 0.01); }  // a point every ray leaves once
};

// Meshes the liver at icosphere subdivision `level` (metres, outward, closed).
vdm::SurfaceMesh make_liver_mesh(int level, int relax_iterations = 8);

}  // namespace vdmsim
