#pragma once
// Parametric instrument geometry in the instrument frame (origin at the tip, +z toward the
// tip, so the shaft runs along -z): a probe is a capsule with its rounded end at the tip; a
// grasper is a shaft ending at the jaw pivot plus two jaws that turn about the pivot's x axis.
#include "render/render_scene.hpp"

namespace render {

// Appends a cylinder along z from z0 to z1 (open ends).
void append_cylinder(SkinMesh& m, double radius, double z0, double z1, int segments);
// Appends a hemisphere of `radius` centred on (0, 0, zc) bulging toward +z (sign = +1) or -z.
void append_hemisphere(SkinMesh& m, double radius, double zc, int sign, int segments);
// Appends a flat disc at z facing +z (sign = +1) or -z.
void append_disc(SkinMesh& m, double radius, double z, int sign, int segments);
// Appends the axis-aligned box [lo, hi] with flat faces.
void append_box(SkinMesh& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi);

SkinMesh probe_mesh(double radius, double length);
// The probe as its collision shape (tools::probe_shape): capsule, cylinder with a rounded
// tip, box (rounded edges) or convex hull.
SkinMesh probe_mesh(const tools::ProbeShape& shape, double radius, double length);
// Appends the solid of revolution about z of a profile (rho, z) with outward normals (nrho,
// nz) per point, from the first point to the last.
void append_lathe(SkinMesh& m, const std::vector<Eigen::Vector2d>& profile, const std::vector<Eigen::Vector2d>& normals,
                  int segments);
SkinMesh grasper_shaft_mesh(double radius, double length, double jaw_length);
// One jaw (side = +1 upper, -1 lower) in the closed position: from the pivot at
// z = -jaw_length to the tip at z = 0.
SkinMesh grasper_jaw_mesh(double radius, double jaw_length, int side);
// The same jaw as it looks (drawn over its collision box, within it): a fenestrated jaw (a
// rounded frame around a window, a solid heel at the pivot) or a Maryland jaw (tapering and
// curving to the side, both jaws alike so that they meet).
SkinMesh grasper_jaw_mesh(double radius, double jaw_length, int side, tools::InstrumentDef::JawLook look);
// An L-hook electrode drawn within a capsule probe of `radius` (tip at z = 0): `shaft`, the
// insulated shaft ending in a taper a little behind the tip, and `hook`, the bare wire that
// leaves it along the axis, turns over at the tip and comes back on the +x side.
struct HookMeshes {
  SkinMesh shaft, hook;
};
HookMeshes probe_hook_meshes(double radius, double length);
// Appends a tube of circular section `tube_radius` along `path` in the x-z plane (y = 0),
// its ends closed by flat discs.
void append_tube(SkinMesh& m, const std::vector<Eigen::Vector2f>& path, float tube_radius, int segments);
// Appends a bar of rectangular section swept along `path` in the x-z plane: `half_width[i]`
// across the path in that plane at path[i], spanning y in [y0, y1]; flat faces; `closed`: the
// path is a loop (else its ends are capped).
void append_sweep(SkinMesh& m, const std::vector<Eigen::Vector2f>& path, const std::vector<float>& half_width, float y0,
                  float y1, bool closed);
// The rotation of a jaw about the pivot for an opening in [0, 1] (tools::jaw_transform).
Eigen::Isometry3f jaw_transform(double jaw_length, double opening, int side);

}  // namespace render
