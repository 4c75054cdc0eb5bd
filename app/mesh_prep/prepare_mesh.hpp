#pragma once
// vdmsim prepare-mesh: a scanned surface in, an organ surface out (closed, outward, manifold,
// even triangles, metres), with a before/after report and progress lines.
#include <ostream>
#include <string>

namespace vdmsim {

// The most nodes prepare-mesh makes (--nodes, or what --edge-length gives over the area).
constexpr int kMaxPreparedNodes = 1000000;

struct PrepareMeshOptions {
  std::string in, out;
  double scale = 1.0;        // input units to metres
  int nodes = 0;             // target node count (0: --edge-length, or 10000 when neither)
  double edge_length = 0;    // target edge in metres (after scale)
  bool center = false;       // move the bounding box's centre to the origin
  int iterations = 5;        // isotropic remeshing passes
  double smoothing = 0.1;    // smoothing time step over the squared target edge (0: none)
};

int cmd_prepare_mesh(const PrepareMeshOptions& options, std::ostream& out, std::ostream& err);

// The edge length whose near-equilateral triangles cover `area` with about `nodes` nodes:
// a closed triangle surface has 2 triangles per node, each of area sqrt(3)/4 L^2.
double edge_length_for_nodes(double area, int nodes);
// Its inverse: about how many nodes an edge of `edge` gives over `area`.
double nodes_for_edge_length(double area, double edge);

}  // namespace vdmsim
