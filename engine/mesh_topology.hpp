#pragma once
// Topology of a triangle surface: unique edges and the checks an organ surface must pass
// (closed 2-manifold, consistently oriented outward, finite, no zero-area triangle, one piece).
#include <array>
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

// Unique undirected edges (i < j), sorted.
std::vector<std::array<int, 2>> unique_edges(const TriMat& tris);

enum class MeshProblem {
  none,
  empty,                    // no nodes or no triangles
  bad_index,                // a triangle refers to a node that does not exist
  non_finite,               // NaN or Inf coordinate
  degenerate_triangle,      // zero area (or repeated node)
  non_manifold_edge,        // an edge shared by more than two triangles
  open_boundary,            // an edge used by one triangle only: the surface has a hole
  inconsistent_orientation, // two neighbours traverse their shared edge the same way
  non_manifold_vertex,      // the triangles around a node do not form one fan
  multiple_components,      // more than one connected piece
  zero_volume,              // closed but encloses no volume
  self_intersection,        // two triangles pass through each other (found by the app's CGAL test,
                            // app/mesh_prep/self_intersections.hpp, not by check_and_orient_surface)
};

const char* to_string(MeshProblem p);

struct MeshCheck {
  MeshProblem problem = MeshProblem::none;
  std::string message;       // what is wrong, naming the triangle, edge or node
  bool flipped = false;      // the whole surface was inward and has been flipped outward
  bool ok() const { return problem == MeshProblem::none; }
};

// Validates `mesh` as an organ surface. If the surface is closed and consistent but
// oriented inward, its triangles are flipped in place and `flipped` is set.
MeshCheck check_and_orient_surface(SurfaceMesh& mesh);

// True when every edge is shared by exactly two triangles (a watertight surface), whatever
// else is wrong with the mesh.
bool is_closed(const TriMat& tris);

// Removes nodes that no triangle uses and renumbers the triangles. Returns how many went.
int drop_unreferenced_nodes(SurfaceMesh& mesh);

}  // namespace vdm
