#include "app/mesh_prep/ray_locate.hpp"

#include <cmath>
#include <iomanip>
#include <limits>

#include "app/scene/mesh_io.hpp"

namespace vdmsim {

RayHit first_hit(const vdm::SurfaceMesh& mesh, const vdm::Vec3& from, const vdm::Vec3& direction) {
  RayHit best;
  const double len = direction.norm();
  if (!(len > 0)) return best;
  const vdm::Vec3 d = direction / len;
  best.distance = std::numeric_limits<double>::infinity();
  for (int k = 0; k < mesh.triangle_count(); ++k) {
    const vdm::Vec3 a = mesh.positions.row(mesh.triangles(k, 0)), b = mesh.positions.row(mesh.triangles(k, 1)),
                    c = mesh.positions.row(mesh.triangles(k, 2));
    const vdm::Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
    const double det = e1.dot(p);
    const double scale = e1.norm() * e2.norm();
    if (std::abs(det) <= 1e-14 * scale) continue;  // parallel to the triangle
    const vdm::Vec3 s = from - a;
    const double u = s.dot(p) / det;
    // Written so that a NaN (from a start so far away that the products overflow) is a miss.
    if (!(u >= 0 && u <= 1)) continue;
    const vdm::Vec3 q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (!(v >= 0 && u + v <= 1)) continue;
    const double t = e2.dot(q) / det;
    if (!(t >= 0 && t < best.distance)) continue;
    // A start so far from the surface that from + t d has lost the triangle's digits is a miss.
    const vdm::Vec3 point = from + t * d;
    if (!((point - a).norm() <= 2 * (e1.norm() + e2.norm()))) continue;
    best.hit = true;
    best.distance = t;
    best.triangle = k;
    best.point = point;
    best.normal = e1.cross(e2).normalized();
  }
  if (!best.hit) best.distance = 0;
  return best;
}

int cmd_locate(const std::string& mesh_path, double scale, const vdm::Vec3& from, const vdm::Vec3& toward,
               std::ostream& out, std::ostream& err) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    err << "vdmsim: error: --scale must be a positive number (0.001 for millimetres)\n";
    return 2;
  }
  if (!from.allFinite() || !toward.allFinite() || !(toward.norm() > 0)) {
    err << "vdmsim: error: --toward must be a non-zero direction and --from a finite point\n";
    return 2;
  }
  MeshLoadOptions opt;
  opt.scale = scale;
  const MeshLoadResult r = load_surface_mesh(mesh_path, opt);
  if (!r.ok) {
    err << "vdmsim: error: " << r.error << "\n";
    return 2;
  }
  const RayHit h = first_hit(r.mesh, from, toward);
  if (!h.hit) {
    const vdm::Vec3 lo = r.mesh.positions.colwise().minCoeff(), hi = r.mesh.positions.colwise().maxCoeff();
    err << "vdmsim: error: " << mesh_path << ": the ray from (" << from.x() << ", " << from.y() << ", " << from.z()
        << ") toward (" << toward.x() << ", " << toward.y() << ", " << toward.z()
        << ") misses the surface (which spans [" << lo.x() << ", " << lo.y() << ", " << lo.z() << "] to [" << hi.x()
        << ", " << hi.y() << ", " << hi.z() << "] m after --scale)\n";
    return 2;
  }
  out << std::setprecision(9);
  out << "point: " << h.point.x() << " " << h.point.y() << " " << h.point.z() << "\n";
  out << "normal: " << h.normal.x() << " " << h.normal.y() << " " << h.normal.z() << "\n";
  out << "distance: " << h.distance << "\n";
  out << "triangle: " << h.triangle << "\n";
  if (h.normal.dot(toward) > 0)
    out << "note: the ray leaves the surface here (it starts inside the organ)\n";
  return 0;
}

}  // namespace vdmsim
