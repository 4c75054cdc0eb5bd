#include "app/mesh_prep/mesh_quality.hpp"

#include <algorithm>
#include <cmath>

#include "engine/geometry.hpp"
#include "engine/mesh_topology.hpp"

namespace vdmsim {

double smallest_angle_deg(const vdm::Vec3& a, const vdm::Vec3& b, const vdm::Vec3& c) {
  auto angle = [](const vdm::Vec3& p, const vdm::Vec3& q, const vdm::Vec3& r) {
    const vdm::Vec3 u = q - p, v = r - p;
    const double s = u.cross(v).norm(), d = u.dot(v);
    return std::atan2(s, d);
  };
  const double m = std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
  return m * 180.0 / M_PI;
}

MeshQuality measure_mesh(const vdm::SurfaceMesh& mesh) {
  MeshQuality q;
  q.nodes = mesh.node_count();
  q.triangles = mesh.triangle_count();
  if (q.nodes == 0 || q.triangles == 0) return q;
  const vdm::NodeMat& x = mesh.positions;
  q.lo = x.colwise().minCoeff().transpose();
  q.hi = x.colwise().maxCoeff().transpose();
  q.volume = vdm::enclosed_volume(x, mesh.triangles, 0.5 * (q.lo + q.hi));
  q.area = vdm::surface_area(x, mesh.triangles);
  q.smallest_angle_deg = 180.0;
  for (int k = 0; k < q.triangles; ++k) {
    const vdm::Vec3 a = x.row(mesh.triangles(k, 0)), b = x.row(mesh.triangles(k, 1)), c = x.row(mesh.triangles(k, 2));
    q.smallest_angle_deg = std::min(q.smallest_angle_deg, smallest_angle_deg(a, b, c));
  }
  const auto edges = vdm::unique_edges(mesh.triangles);
  double sum = 0;
  for (const auto& e : edges) sum += (x.row(e[0]) - x.row(e[1])).norm();
  q.mean_edge = edges.empty() ? 0 : sum / double(edges.size());
  return q;
}

}  // namespace vdmsim
