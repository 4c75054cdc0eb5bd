#pragma once
// Turning a scanned organ surface (a triangle soup from a CT segmentation: duplicate and
// degenerate triangles, holes, a crop, self-intersections, bumps) into a closed, outward,
// manifold surface of even triangles, with CGAL's Polygon Mesh Processing.
#include <functional>
#include <string>

#include "engine/types.hpp"

namespace vdmsim {

using ProgressFn = std::function<void(const std::string&)>;

struct RepairReport {
  int triangles_in = 0;
  int soup_triangles_removed = 0;   // duplicate or degenerate triangles, by the soup repair
  int components_dropped = 0;       // pieces other than the largest
  int holes_filled = 0;
  int largest_hole_edges = 0;
  int self_intersections = 0;       // crossing triangle pairs found before their repair
  bool self_intersections_left = false;
  std::string crossings_method;     // how the crossings went: "outer surface kept" or "local repair"
  bool closed = false;
  std::string error;                // what could not be repaired ("" when the surface is sound)
};

// Repairs `mesh` in place (any triangles in; a closed manifold outward surface out, when it
// returns true).
bool repair_surface(vdm::SurfaceMesh& mesh, RepairReport& report, const ProgressFn& progress);

struct RemeshOptions {
  double edge_length = 0;   // target edge (mesh units)
  int iterations = 5;       // isotropic remeshing passes
  int smoothing_steps = 2;       // shape smoothing (implicit mean curvature flow) steps, volume restored after
  double smoothing = 0.1;        // their time step over the squared target edge (0: no smoothing)
};

// Remeshes the closed surface `mesh` to triangles of edge near `edge_length`, smooths it
// lightly, evens its angles, and scales it about its centroid back to its volume.
bool remesh_surface(vdm::SurfaceMesh& mesh, const RemeshOptions& options, std::string& error,
                    const ProgressFn& progress);

}  // namespace vdmsim
