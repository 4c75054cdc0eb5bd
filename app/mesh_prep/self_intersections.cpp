#include "app/mesh_prep/self_intersections.hpp"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <iterator>
#include <map>
#include <sstream>

#include "app/mesh_prep/cgal_surface.hpp"

namespace vdmsim {
namespace PMP = CGAL::Polygon_mesh_processing;

std::string SelfIntersections::text(size_t shown) const {
  std::ostringstream s;
  for (size_t i = 0; i < pairs.size() && i < shown; ++i)
    s << (i ? ", " : "") << "triangles " << pairs[i][0] << " and " << pairs[i][1];
  if (pairs.size() > shown) s << ", ...";
  return s.str();
}

namespace {
// Stops the search once `limit` pairs are in.
struct Enough {};
struct PairSink {
  std::vector<std::pair<cgal::Mesh::Face_index, cgal::Mesh::Face_index>>* pairs;
  size_t limit;
  PairSink& operator*() { return *this; }
  PairSink& operator++() { return *this; }
  PairSink& operator++(int) { return *this; }
  PairSink& operator=(const std::pair<cgal::Mesh::Face_index, cgal::Mesh::Face_index>& p) {
    pairs->push_back(p);
    if (pairs->size() >= limit) throw Enough{};
    return *this;
  }
};
}  // namespace

SelfIntersections find_self_intersections(const vdm::SurfaceMesh& mesh, size_t max_pairs) {
  SelfIntersections out;
  cgal::Mesh m;
  std::vector<cgal::Mesh::Face_index> face_of;
  if (!cgal::to_cgal(mesh, m, &face_of)) return out;
  out.tested = true;
  std::vector<std::pair<cgal::Mesh::Face_index, cgal::Mesh::Face_index>> found;
  try {
    PMP::self_intersections(m, PairSink{&found, std::max<size_t>(max_pairs, 1)});
  } catch (const Enough&) {
  }
  std::map<cgal::Mesh::Face_index, int> triangle_of;
  for (size_t k = 0; k < face_of.size(); ++k) triangle_of[face_of[k]] = static_cast<int>(k);
  for (const auto& [f, g] : found) {
    const int a = triangle_of[f], b = triangle_of[g];
    out.pairs.push_back({std::min(a, b), std::max(a, b)});
  }
  out.any = !out.pairs.empty();
  return out;
}

}  // namespace vdmsim
