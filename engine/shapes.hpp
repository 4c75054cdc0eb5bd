#pragma once
// Closed test surfaces generated in code: boxes (cube, beam) and spheres. Used by the
// paper experiments, tests and benchmarks.
#include "engine/types.hpp"

namespace vdm {

// Axis-aligned box centred at `center` with side lengths `size` (m), each face a grid of
// nx x ny (etc.) quads, every quad split into four triangles about its centre node so the
// mesh has all the mirror symmetries of the box.
SurfaceMesh make_box(const Vec3& size, int nx, int ny, int nz, const Vec3& center = Vec3::Zero());

// Icosphere of radius r: an icosahedron subdivided `levels` times, projected to the sphere.
SurfaceMesh make_icosphere(double radius, int levels, const Vec3& center = Vec3::Zero());

// Latitude-longitude sphere (poles are valence `segments` nodes): an irregular sphere.
SurfaceMesh make_uv_sphere(double radius, int rings, int segments, const Vec3& center = Vec3::Zero());

}  // namespace vdm
