#pragma once
// A bound on the FEM's tetrahedra, checked before gmsh is asked for them: a tet_size far below
// the organ's size would otherwise mesh for minutes while memory grows without bound.
#include <string>

#include "engine/types.hpp"

namespace vdmsim {

// The most tetrahedra a tet_size may ask for (about 2 GB of FEM model and minutes of gmsh).
constexpr double kMaxTets = 5e6;

// The fewest tetrahedra with edges at most `edge` (m) that fill `volume` (m^3): the volume over
// that of a regular tetrahedron of edge `edge` (gmsh's meshes have at least this many).
double tets_needed(double volume, double edge);

// False, with a message naming the estimate, the bound and the smallest tet_size within it,
// when tets of edge `edge` (m; 0: graded from the surface, not checked) in the closed outward
// surface `surface` would be more than kMaxTets.
bool check_tet_budget(const vdm::SurfaceMesh& surface, double edge, std::string& error);

}  // namespace vdmsim
