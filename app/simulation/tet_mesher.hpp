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

}  // namespace vdmsim
