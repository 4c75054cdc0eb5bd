#include "app/mesh_prep/surface_distance.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vdmsim {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Kernel::Point_3 point(const vdm::Vec3& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

SurfaceDistance sampled_distance(const vdm::SurfaceMesh& from, const vdm::SurfaceMesh& to, int samples) {
  SurfaceDistance out;
  if (from.triangle_count() == 0 || to.triangle_count() == 0) return out;
  std::vector<Triangle> triangles;
  triangles.reserve(static_cast<size_t>(to.triangle_count()));
  for (int k = 0; k < to.triangle_count(); ++k) {
    const vdm::Vec3 a = to.positions.row(to.triangles(k, 0)), b = to.positions.row(to.triangles(k, 1)),
                    c = to.positions.row(to.triangles(k, 2));
    const Triangle t(point(a), point(b), point(c));
    if (!t.is_degenerate()) triangles.push_back(t);
  }
  if (triangles.empty()) return out;
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();

  double sum = 0;
  auto measure = [&](const vdm::Vec3& p) {
    const double d = std::sqrt(tree.squared_distance(point(p)));
    sum += d;
    out.max = std::max(out.max, d);
    ++out.samples;
  };
  for (int i = 0; i < from.node_count(); ++i) measure(from.positions.row(i).transpose());
  double total_area = 0;
  std::vector<double> area(static_cast<size_t>(from.triangle_count()));
  for (int k = 0; k < from.triangle_count(); ++k) {
    const vdm::Vec3 a = from.positions.row(from.triangles(k, 0)), b = from.positions.row(from.triangles(k, 1)),
                    c = from.positions.row(from.triangles(k, 2));
    area[k] = 0.5 * (b - a).cross(c - a).norm();
    total_area += area[k];
  }
  // Per triangle, a regular grid of barycentric points as dense as its share of the samples.
  const int extra = std::max(0, samples - from.node_count());
  for (int k = 0; k < from.triangle_count(); ++k) {
    const vdm::Vec3 a = from.positions.row(from.triangles(k, 0)), b = from.positions.row(from.triangles(k, 1)),
                    c = from.positions.row(from.triangles(k, 2));
    const double want = total_area > 0 ? extra * area[k] / total_area : 0;
    const int m = std::max(1, static_cast<int>(std::ceil((std::sqrt(8 * want + 1) - 1) / 2)));  // m(m+1)/2 >= want
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        const double u = (i + 1.0 / 3.0) / m, v = (j + 1.0 / 3.0) / m;
        measure(a + u * (b - a) + v * (c - a));
      }
  }
  out.mean = out.samples ? sum / out.samples : 0;
  return out;
}

}  // namespace vdmsim
