#pragma once
// Internal to app/mesh_prep's CGAL translation units (include it from nowhere else: CGAL's
// headers are heavy): the organ surface as a CGAL Surface_mesh, and back.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim::cgal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

// Builds the halfedge mesh of `in`. False when a triangle cannot be added (a non-manifold
// edge or node, or a triangle that repeats a node): the surface is then no halfedge mesh.
// `face_of_triangle[k]` is the mesh face of triangle k (so results can name triangles).
bool to_cgal(const vdm::SurfaceMesh& in, Mesh& out, std::vector<Mesh::Face_index>* face_of_triangle = nullptr);

// The mesh as plain arrays (garbage collected, vertices in the mesh's order).
vdm::SurfaceMesh from_cgal(const Mesh& mesh);

}  // namespace vdmsim::cgal
