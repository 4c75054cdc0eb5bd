#pragma once
// Tetrahedral meshes of a closed organ surface, made by gmsh (libgmsh API). The surface's
// nodes and triangles are kept as they are (a discrete gmsh surface): the tet mesh's first
// nodes are the surface's nodes in the same order, so the FEM and VDM models of an organ share
// their surface. The engine never sees gmsh: it gets a plain TetMesh.
#include <string>

#include "engine/fem/tet_mesh.hpp"

namespace vdmsim {

// How the inside is sized: like the surface's edges nearby (graded), or growing to max_size
// away from the surface (coarse: far fewer nodes inside a finely meshed organ).
enum class TetInterior { graded, coarse };

// `max_size`: largest tet edge (m); 0 = let gmsh grade from the surface's own edge lengths.
bool tetrahedralize(const vdm::SurfaceMesh& surface, double max_size, vdm::fem::TetMesh& out, std::string& error,
                    TetInterior interior = TetInterior::graded);

// An axis-aligned box with a disk drawn on the middle of its top face (z = max): the disk's rim
// is a line of the mesh, so the nodes on the disk are exactly those within `disk_radius` of
// the top's centre. Tets graded from `h_min` at the rim, growing by `grade` per metre of
// distance from it, up to `h_max` (gmsh, OpenCASCADE box and a size field). For a flat
// punch's reference FEM: fine where the punch's edge concentrates the strain, coarse away.
// The surface is the tets' boundary, its nodes first (outward triangles).
struct BoxWithDisk {
  vdm::Vec3 size = vdm::Vec3(0.1, 0.1, 0.05);  // m
  vdm::Vec3 center = vdm::Vec3::Zero();
  double disk_radius = 0.005;  // m
  double h_min = 0.001;        // m, tet size at the rim
  double grade = 0.3;          // size growth per unit distance from the rim
  double h_max = 0.01;         // m
};
bool mesh_box_with_disk(const BoxWithDisk& spec, vdm::fem::TetMesh& out, std::string& error);

}  // namespace vdmsim
