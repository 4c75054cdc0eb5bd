// remesh_surface (app/mesh_prep/surface_repair.hpp), apart from repair_surface: each half
// instantiates a large part of CGAL's Polygon Mesh Processing, and as two files they compile in
// parallel (together they were the build's slowest object by far).
#include "app/mesh_prep/surface_repair.hpp"

#include <CGAL/Polygon_mesh_processing/angle_and_area_smoothing.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/smooth_shape.h>
#include <CGAL/boost/graph/helpers.h>

#include <cmath>
#include <sstream>

#include "app/mesh_prep/cgal_surface.hpp"
#include "app/mesh_prep/mesh_quality.hpp"

namespace vdmsim {
namespace PMP = CGAL::Polygon_mesh_processing;
using cgal::Mesh;

namespace {

void say(const ProgressFn& progress, const std::string& text) {
  if (progress) progress(text);
}

}  // namespace

bool remesh_surface(vdm::SurfaceMesh& mesh, const RemeshOptions& opt, std::string& error, const ProgressFn& progress) {
  Mesh m;
  if (!cgal::to_cgal(mesh, m) || !CGAL::is_closed(m)) {
    error = "the surface to remesh is not a closed manifold";
    return false;
  }
  const double volume0 = measure_mesh(mesh).volume;
  const double L = opt.edge_length;
  {
    std::ostringstream s;
    s << "remesh: isotropic remeshing to edges of " << L << " (" << opt.iterations << " passes)";
    say(progress, s.str());
  }
  PMP::isotropic_remeshing(faces(m), L, m,
                           CGAL::parameters::number_of_iterations(static_cast<unsigned>(opt.iterations))
                               .number_of_relaxation_steps(3));
  m.collect_garbage();
  if (opt.smoothing_steps > 0 && opt.smoothing > 0) {
    say(progress, "remesh: smoothing (volume restored after)");
    PMP::smooth_shape(m, opt.smoothing * L * L,
                      CGAL::parameters::number_of_iterations(static_cast<unsigned>(opt.smoothing_steps)));
  }
  say(progress, "remesh: evening the angles");
  PMP::angle_and_area_smoothing(m, CGAL::parameters::number_of_iterations(10)
                                       .use_angle_smoothing(true)
                                       .use_area_smoothing(false)
                                       .do_project(true));
  m.collect_garbage();
  // Where two sheets of the surface lie within an edge of each other (a tight fold), the new
  // triangles may cross: those are removed and the openings patched, locally.
  for (int pass = 0; pass < 3 && PMP::does_self_intersect(m); ++pass) {
    say(progress, "remesh: the new triangles cross where the surface folds tightly; repairing them locally");
    PMP::experimental::remove_self_intersections(m, CGAL::parameters::preserve_genus(false));
    m.collect_garbage();
    if (!CGAL::is_closed(m)) break;
    // The patches' triangles are uneven: one more pass evens them.
    PMP::isotropic_remeshing(faces(m), L, m, CGAL::parameters::number_of_iterations(2).number_of_relaxation_steps(3));
    PMP::angle_and_area_smoothing(m, CGAL::parameters::number_of_iterations(10)
                                         .use_angle_smoothing(true)
                                         .use_area_smoothing(false)
                                         .do_project(true));
    m.collect_garbage();
  }
  if (PMP::does_self_intersect(m)) {
    error = "the remeshed surface passes through itself where it folds tightly (try a shorter --edge-length)";
    return false;
  }
  if (!CGAL::is_closed(m)) {
    error = "the local repair of crossing triangles left the surface open";
    return false;
  }
  vdm::SurfaceMesh out = cgal::from_cgal(m);
  const MeshQuality q = measure_mesh(out);
  if (!(q.volume > 0) || !(volume0 > 0)) {
    error = "the remeshed surface encloses no volume";
    return false;
  }
  // Scale about the centroid of the nodes back to the volume before smoothing.
  const vdm::Vec3 c = out.positions.colwise().mean().transpose();
  const double s = std::cbrt(volume0 / q.volume);
  for (int i = 0; i < out.node_count(); ++i) out.positions.row(i) = (c + s * (out.positions.row(i).transpose() - c)).transpose();
  mesh = std::move(out);
  return true;
}

}  // namespace vdmsim
