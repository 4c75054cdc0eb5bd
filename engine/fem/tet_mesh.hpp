#pragma once
// Tetrahedral meshes for the finite-element reference (engine/fem). The first
// `surface_nodes` nodes are the nodes of the boundary surface, in the same order as the
// SurfaceMesh the organ is defined by, so that loads, constraints and displacements on the
// surface mean the same node for every model (vdm, fem, mass_spring).
#include <string>

#include "engine/types.hpp"

namespace vdm::fem {

using TetMat = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;  // T x 4 node indices

struct TetMesh {
  NodeMat positions;      // N x 3 rest positions (m); rows [0, surface_nodes) are the surface
  TetMat tets;            // T x 4, positively oriented: (x1-x0).((x2-x0) x (x3-x0)) > 0
  SurfaceMesh surface;    // the boundary: positions = first surface_nodes rows, outward
  int surface_nodes = 0;
  int node_count() const { return static_cast<int>(positions.rows()); }
  int tet_count() const { return static_cast<int>(tets.rows()); }
};

// Signed volume of tet (a, b, c, d) (m^3), positive when positively oriented.
double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Structured tets of an axis-aligned box: every cell of an nx x ny x nz grid gets a node at its
// centre and at the centre of each face and is split into 24 tets (each face's four
// triangles about its centre, coned to the cell centre). The mesh has all the mirror
// symmetries of the box, and its boundary is exactly make_box(size, nx, ny, nz, center)
// (same nodes, same order, same triangles).
TetMesh make_box_tets(const Vec3& size, int nx, int ny, int nz, const Vec3& center = Vec3::Zero());

// Checks a tet mesh made elsewhere (gmsh): indices in range, positive volumes, boundary
// triangles (faces of one tet) forming `surface` on the first surface_nodes nodes. Fills
// surface.triangles from the tets when it is empty. False with a message on a problem.
bool check_tet_mesh(TetMesh& mesh, std::string& error);

}  // namespace vdm::fem
