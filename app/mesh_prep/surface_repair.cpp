#include "app/mesh_prep/surface_repair.hpp"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <iterator>

#include "app/mesh_prep/cgal_surface.hpp"

namespace vdmsim {
namespace PMP = CGAL::Polygon_mesh_processing;
using cgal::Mesh;
using cgal::Point;

namespace {

void say(const ProgressFn& progress, const std::string& text) {
  if (progress) progress(text);
}

// Holes (border cycles) closed by a triangulation refined to the density around them: a small
// hole gets a small patch, a crop's flat opening a flat cap.
void fill_holes(Mesh& m, RepairReport& report) {
  std::vector<Mesh::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(m, std::back_inserter(cycles));
  for (Mesh::Halfedge_index h : cycles) {
    int edges = 0;
    for (Mesh::Halfedge_index g : CGAL::halfedges_around_face(h, m)) {
      (void)g;
      ++edges;
    }
    std::vector<Mesh::Face_index> patch;
    std::vector<Mesh::Vertex_index> added;
    PMP::triangulate_and_refine_hole(m, h, std::back_inserter(patch), std::back_inserter(added));
    if (!patch.empty()) {
      ++report.holes_filled;
      report.largest_hole_edges = std::max(report.largest_hole_edges, edges);
    }
  }
}

// Crossing triangles: CGAL's local repair first (the crossing faces and their neighbours
// removed, the opening patched smoothly), which suits a folded-over triangle or a small fold;
// else the outer surface (the triangles cut along their intersections and the inner parts
// dropped), which suits a large part pushed through another.
bool remove_crossings(Mesh& m, std::string& method) {
  const double area = PMP::area(m);
  Mesh local = m;
  PMP::experimental::remove_self_intersections(local, CGAL::parameters::preserve_genus(false));
  local.collect_garbage();
  if (CGAL::is_closed(local) && !PMP::does_self_intersect(local)) {
    m = std::move(local);
    method = "local repair";
    return true;
  }
  Mesh refined = m;
  bool ok = false;
  try {
    ok = PMP::experimental::autorefine_and_remove_self_intersections(refined);
  } catch (const std::exception&) {
    ok = false;
  }
  if (ok && CGAL::is_closed(refined)) {
    PMP::keep_largest_connected_components(refined, 1);
    refined.collect_garbage();
  }
  // Kept when it is the organ's outer surface, not a sliver of it.
  if (ok && CGAL::is_closed(refined) && !PMP::does_self_intersect(refined) && PMP::area(refined) > 0.7 * area) {
    m = std::move(refined);
    method = "outer surface kept";
    return true;
  }
  m = std::move(local);
  method = "local repair, incomplete";
  return false;
}

}  // namespace

bool repair_surface(vdm::SurfaceMesh& mesh, RepairReport& report, const ProgressFn& progress) {
  report = RepairReport{};
  report.triangles_in = mesh.triangle_count();
  std::vector<Point> points;
  std::vector<std::array<std::size_t, 3>> soup;
  for (int i = 0; i < mesh.node_count(); ++i)
    points.emplace_back(mesh.positions(i, 0), mesh.positions(i, 1), mesh.positions(i, 2));
  for (int k = 0; k < mesh.triangle_count(); ++k)
    soup.push_back({std::size_t(mesh.triangles(k, 0)), std::size_t(mesh.triangles(k, 1)), std::size_t(mesh.triangles(k, 2))});
  say(progress, "repair: duplicate and degenerate triangles");
  PMP::repair_polygon_soup(points, soup);
  report.soup_triangles_removed = report.triangles_in - static_cast<int>(soup.size());
  if (soup.empty()) {
    report.error = "no triangle is left after removing the degenerate and duplicate ones";
    return false;
  }
  PMP::orient_polygon_soup(points, soup);
  Mesh m;
  PMP::polygon_soup_to_polygon_mesh(points, soup, m);
  PMP::stitch_borders(m);
  PMP::remove_degenerate_faces(m);
  PMP::duplicate_non_manifold_vertices(m);
  report.components_dropped = static_cast<int>(PMP::keep_largest_connected_components(m, 1));
  PMP::remove_isolated_vertices(m);
  m.collect_garbage();

  say(progress, "repair: holes");
  fill_holes(m, report);
  m.collect_garbage();

  // Outward before the crossings are resolved: which side is "outer" follows the orientation.
  if (CGAL::is_closed(m) && !PMP::is_outward_oriented(m)) PMP::reverse_face_orientations(m);

  say(progress, "repair: self-intersections");
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> crossing;
  PMP::self_intersections(m, std::back_inserter(crossing));
  report.self_intersections = static_cast<int>(crossing.size());
  if (!crossing.empty()) {
    report.self_intersections_left = !remove_crossings(m, report.crossings_method);
    fill_holes(m, report);  // the local repair may leave openings
    m.collect_garbage();
  }
  report.closed = CGAL::is_closed(m);
  if (report.closed && !PMP::is_outward_oriented(m)) PMP::reverse_face_orientations(m);
  mesh = cgal::from_cgal(m);
  if (!report.closed) report.error = "the surface could not be closed";
  else if (report.self_intersections_left) report.error = "self-intersections remain after the repair";
  return report.error.empty();
}

}  // namespace vdmsim
