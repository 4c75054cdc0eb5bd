#include "engine/convex_hull.hpp"

#include "engine/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace vdm {
namespace {

// Closest point to p on triangle abc.
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 w = closest_barycentric(p, a, b, c);
  return w[0] * a + w[1] * b + w[2] * c;
}

struct Face {
  std::array<int, 3> v;
  Vec3 n;
  double d;
  bool alive = true;
};

Face make_face(const std::vector<Vec3>& p, int a, int b, int c) {
  Face f;
  f.v = {a, b, c};
  f.n = (p[b] - p[a]).cross(p[c] - p[a]).normalized();
  f.d = f.n.dot(p[a]);
  return f;
}

}  // namespace

bool convex_hull(const std::vector<Vec3>& p, ConvexHull& out, std::string& error) {
  out = ConvexHull();
  if (p.size() < 4) {
    error = "a convex shape needs at least 4 points, got " + std::to_string(p.size());
    return false;
  }
  if (p.size() > kMaxHullPoints) {
    error = "the convex shape has " + std::to_string(p.size()) + " points, more than the limit of " +
            std::to_string(kMaxHullPoints) + ": simplify (decimate) its mesh";
    return false;
  }
  // Extent and tolerance.
  Vec3 lo = p[0], hi = p[0];
  for (const Vec3& q : p) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const double extent = (hi - lo).norm();
  const double eps = 1e-9 * std::max(extent, 1e-300);
  // A first tetrahedron: two far-apart points, the farthest from their line, the farthest
  // from their plane.
  int i0 = 0, i1 = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    if (p[i].x() < p[i0].x()) i0 = int(i);
    if (p[i].x() > p[i1].x()) i1 = int(i);
  }
  if ((p[i1] - p[i0]).norm() <= eps)
    for (size_t i = 0; i < p.size(); ++i)
      if ((p[i] - p[i0]).norm() > (p[i1] - p[i0]).norm()) i1 = int(i);
  const Vec3 dir = (p[i1] - p[i0]).normalized();
  int i2 = -1;
  double best = eps;
  for (size_t i = 0; i < p.size(); ++i) {
    const double dist = (p[i] - p[i0] - dir * dir.dot(p[i] - p[i0])).norm();
    if (dist > best) best = dist, i2 = int(i);
  }
  if (i2 < 0 || (p[i1] - p[i0]).norm() <= eps) {
    error = "the convex shape's points lie on one line: they span no volume";
    return false;
  }
  const Vec3 pn = (p[i1] - p[i0]).cross(p[i2] - p[i0]).normalized();
  int i3 = -1;
  best = 1e-7 * extent;
  for (size_t i = 0; i < p.size(); ++i) {
    const double dist = std::abs(pn.dot(p[i] - p[i0]));
    if (dist > best) best = dist, i3 = int(i);
  }
  if (i3 < 0) {
    error = "the convex shape's points lie on one plane: they span no volume";
    return false;
  }
  std::vector<Face> faces;
  const Vec3 inside = (p[i0] + p[i1] + p[i2] + p[i3]) / 4.0;
  for (const auto& t : {std::array<int, 3>{i0, i1, i2}, {i0, i1, i3}, {i0, i2, i3}, {i1, i2, i3}}) {
    Face f = make_face(p, t[0], t[1], t[2]);
    if (f.n.dot(inside) > f.d) f = make_face(p, t[0], t[2], t[1]);
    faces.push_back(f);
  }
  // Add the points one at a time: remove the faces that see the point, close the hole with
  // faces from its horizon edges to the point.
  std::vector<int> visible;
  std::map<std::pair<int, int>, int> edges;
  for (size_t pi = 0; pi < p.size(); ++pi) {
    const int q = int(pi);
    if (q == i0 || q == i1 || q == i2 || q == i3) continue;
    visible.clear();
    for (size_t k = 0; k < faces.size(); ++k)
      if (faces[k].alive && faces[k].n.dot(p[q]) - faces[k].d > eps) visible.push_back(int(k));
    if (visible.empty()) continue;
    // Directed edges of the visible faces; an edge whose reverse is not visible is horizon.
    edges.clear();
    for (int k : visible)
      for (int e = 0; e < 3; ++e) edges[{faces[k].v[e], faces[k].v[(e + 1) % 3]}] = k;
    for (int k : visible) faces[k].alive = false;
    for (const auto& [edge, k] : edges)
      if (!edges.count({edge.second, edge.first})) faces.push_back(make_face(p, edge.first, edge.second, q));
  }
  // Compact: keep the used vertices only.
  std::vector<int> index(p.size(), -1);
  for (const Face& f : faces) {
    if (!f.alive) continue;
    std::array<int, 3> t;
    for (int c = 0; c < 3; ++c) {
      if (index[f.v[c]] < 0) {
        index[f.v[c]] = int(out.vertices.size());
        out.vertices.push_back(p[f.v[c]]);
      }
      t[c] = index[f.v[c]];
    }
    out.triangles.push_back(t);
    out.normals.push_back(f.n);
    out.offsets.push_back(f.d);
  }
  out.lo = out.hi = out.vertices.front();
  for (const Vec3& v : out.vertices) {
    out.lo = out.lo.cwiseMin(v);
    out.hi = out.hi.cwiseMax(v);
    out.centroid += v / double(out.vertices.size());
    out.bound = std::max(out.bound, v.norm());
  }
  out.inradius = 1e300;
  for (size_t k = 0; k < out.normals.size(); ++k)
    out.inradius = std::min(out.inradius, out.offsets[k] - out.normals[k].dot(out.centroid));
  if (!(out.inradius > 0)) {
    error = "the convex shape is degenerate (no interior)";
    return false;
  }
  // Guard against round-off on nearly coplanar input (CAD meshes): the result must be closed
  // (every directed edge met once, its reverse once) and convex (every point on or inside
  // every face plane, to a tolerance relative to the extent).
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : out.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) {
      error = "the convex hull came out open (nearly coplanar points): simplify the mesh";
      return false;
    }
  }
  for (size_t k = 0; k < out.normals.size(); ++k)
    for (const Vec3& q : p)
      if (out.normals[k].dot(q) - out.offsets[k] > 1e3 * eps) {
        error = "the convex hull came out non-convex (nearly coplanar points): simplify the mesh";
        return false;
      }
  return true;
}

double convex_hull_distance(const ConvexHull& h, const Vec3& x, Vec3& surface_point, Vec3& normal) {
  // Inside: the nearest face plane (exact for a convex polytope).
  double deepest = -1e300;
  size_t face = 0;
  for (size_t k = 0; k < h.normals.size(); ++k) {
    const double s = h.normals[k].dot(x) - h.offsets[k];
    if (s > deepest) deepest = s, face = k;
  }
  if (deepest <= 0) {
    normal = h.normals[face];
    surface_point = x - deepest * normal;
    return deepest;
  }
  // Outside: the nearest point of the surface triangles.
  double best = 1e300;
  for (const auto& t : h.triangles) {
    const Vec3 c = closest_on_triangle(x, h.vertices[t[0]], h.vertices[t[1]], h.vertices[t[2]]);
    const double d = (x - c).squaredNorm();
    if (d < best) best = d, surface_point = c;
  }
  const double dist = std::sqrt(best);
  normal = dist > 0 ? Vec3((x - surface_point) / dist) : h.normals[face];
  return dist;
}

}  // namespace vdm
