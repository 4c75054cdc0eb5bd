#pragma once
// The project's own organs, smooth implicit shapes meshed by projecting a subdivided
// icosahedron onto them from a centre and relaxing the nodes along the surface (level 4, 5, 6
// give 2562, 10242, 40962 nodes): a liver (a thick right lobe and a thin left lobe blended
// together) and a gallbladder (a pear-shaped sac: a round fundus, a body tapering to its neck).
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

struct GallbladderShape {
  // Implicit function: < 0 inside, 0 on the surface, > 0 outside (dimensionless). The long
  // axis along x, the fundus toward -x, the neck toward +x and turning up (+z) a little.
  double value(const vdm::Vec3& p) const;
  vdm::Vec3 gradient(const vdm::Vec3& p) const;
  vdm::Vec3 center() const { return vdm::Vec3(0.011, 0.0, 0.002); }  // a point every ray leaves once
  // The icosphere's directions are scaled by this before they are cast from the centre, so
  // that the long neck gets its share of the nodes (as a sphere's map onto an ellipsoid).
  vdm::Vec3 stretch() const { return vdm::Vec3(0.045, 0.016, 0.015); }
};

// Meshes the gallbladder at icosphere subdivision `level` (metres, outward, closed): about
// 9 cm long and 3 cm across, about 40 ml, as an adult's.
vdm::SurfaceMesh make_gallbladder_mesh(int level, int relax_iterations = 8);

}  // namespace vdmsim
