#pragma once
// Support for the hard-case tests (issue 7): a concrete "sensible shape" check and the
// awkward meshes (slivers, near-zero areas, graded refinement, valence 3 and 12).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/sim_state.hpp"

namespace vdm::hard {

// What "a sensible shape" means here, all of it measured on the current positions:
// - every number in the state is finite;
// - the enclosed volume (recomputed from x) is within 1e-4 of the rest volume;
// - no triangle is collapsed (area above 1e-6 of its rest area) and no edge is folded over:
//   the angle between the normals of its two triangles is at least 150 degrees (a triangle
//   turned over onto its neighbour) and at least 60 degrees more than at rest (so the
//   90-degree edges of a box may sharpen into creases without counting);
// - no node moved further than `max_displacement` (a bound the case's own loading gives).
constexpr double kFoldAngle = 150.0 * M_PI / 180.0, kFoldTurn = 60.0 * M_PI / 180.0;

struct ShapeReport {
  bool finite = true;
  double volume_error = 0;  // relative, recomputed from x
  int collapsed = 0;        // triangles
  int folded = 0;           // edges
  double max_u = 0;         // m
  std::string text() const {
    std::ostringstream o;
    o << "finite " << finite << ", volume error " << volume_error << ", collapsed triangles " << collapsed
      << ", folded edges " << folded << ", max |u| " << max_u;
    return o.str();
  }
};

inline Vec3 tri_normal(const NodeMat& x, const TriMat& t, int k) {
  const Vec3 a = x.row(t(k, 0)), b = x.row(t(k, 1)), c = x.row(t(k, 2));
  return (b - a).cross(c - a);
}

// The pairs of triangles that share an edge (cached for the last mesh asked about).
inline const std::vector<std::pair<int, int>>& triangle_pairs(const TriMat& t) {
  static TriMat cached;
  static std::vector<std::pair<int, int>> pairs;
  if (cached.rows() == t.rows() && cached == t) return pairs;
  cached = t;
  pairs.clear();
  std::map<std::pair<int, int>, int> first;
  for (int k = 0; k < t.rows(); ++k)
    for (int e = 0; e < 3; ++e) {
      const int a = t(k, e), b = t(k, (e + 1) % 3);
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto it = first.find(key);
      if (it == first.end()) first.emplace(key, k);
      else pairs.emplace_back(k, it->second);
    }
  return pairs;
}

inline ShapeReport shape_of(const TissueModel& m, const SimState& s) {
  ShapeReport r;
  r.finite = s.u.allFinite() && s.x.allFinite() && std::isfinite(s.pressure) && s.stress.allFinite() &&
             s.strain.allFinite() && s.reaction.allFinite() && s.reaction_pressure.allFinite() &&
             std::isfinite(s.volume);
  if (!r.finite) return r;
  r.volume_error = std::abs(enclosed_volume(s.x, m.rest.triangles, m.origin) - m.rest_volume) / m.rest_volume;
  r.max_u = s.u.rowwise().norm().maxCoeff();
  const TriMat& t = m.rest.triangles;
  const int nt = static_cast<int>(t.rows());
  std::vector<Vec3> n_now(nt), n_rest(nt);
  for (int k = 0; k < nt; ++k) {
    n_now[k] = tri_normal(s.x, t, k);
    n_rest[k] = tri_normal(m.rest.positions, t, k);
    if (n_now[k].norm() <= 1e-6 * n_rest[k].norm()) ++r.collapsed;
  }
  for (const auto& [k, o] : triangle_pairs(t)) {
    const double now = std::acos(std::clamp(n_now[k].normalized().dot(n_now[o].normalized()), -1.0, 1.0));
    const double rest = std::acos(std::clamp(n_rest[k].normalized().dot(n_rest[o].normalized()), -1.0, 1.0));
    if (now >= kFoldAngle && now - rest >= kFoldTurn) ++r.folded;
  }
  return r;
}

// EXPECTs the shape criterion; `what` names the case and moment. `check_folds` false: only
// finiteness, volume and the displacement bound (past a case's known limit, see the issue note).
inline void expect_sensible(const TissueModel& m, const SimState& s, double max_displacement,
                            const std::string& what, bool check_folds = true) {
  const ShapeReport r = shape_of(m, s);
  EXPECT_FALSE(s.failed) << what << ": step failed: " << s.failure;
  ASSERT_TRUE(r.finite) << what << ": " << r.text();
  EXPECT_LE(r.volume_error, 1e-4) << what << ": " << r.text();
  EXPECT_LE(std::abs(s.volume_rel_error), 1e-4) << what;
  EXPECT_EQ(r.collapsed, 0) << what << ": " << r.text();
  if (check_folds) {
    EXPECT_EQ(r.folded, 0) << what << ": " << r.text();
  }
  EXPECT_LE(r.max_u, max_displacement) << what << ": " << r.text();
}


// For each node, the node at its image under the linear map M (the mesh must have that
// symmetry); -1 where none lies within `tol`.
inline std::vector<int> mirror_map(const NodeMat& x, const Eigen::Matrix3d& M, double tol) {
  std::vector<int> out(static_cast<size_t>(x.rows()), -1);
  for (int i = 0; i < x.rows(); ++i) {
    const Vec3 image = M * Vec3(x.row(i).transpose());
    const int j = nearest_node(x, image);
    if ((x.row(j).transpose() - image).norm() < tol) out[static_cast<size_t>(i)] = j;
  }
  return out;
}

// Remaps one coordinate of a box grid: node coordinate c in [lo, hi] goes to f(c).
template <class F>
void remap_axis(SurfaceMesh& mesh, int axis, F f) {
  for (int i = 0; i < mesh.node_count(); ++i) mesh.positions(i, axis) = f(mesh.positions(i, axis));
}

// A cube of side L (8 x 8 x 8 cells) whose grid line at x = 0 is moved to within L/8 * 1e-4
// of the next one: the face triangles in that column have aspect ratio about 1e4.
inline SurfaceMesh sliver_cube(double L) {
  SurfaceMesh mesh = make_box(Vec3(L, L, L), 8, 8, 8);
  const double h = L / 8, eps = 1e-4 * h;
  remap_axis(mesh, 0, [&](double c) {
    if (std::abs(c) < 1e-12) return h - eps;  // the x = 0 line moves next to x = h
    if (c > 0 && c < h - 1e-12) return h - eps / 2;  // quad-centre nodes between them
    return c;
  });
  return mesh;
}

// An icosphere whose node `centre` has its 1-ring pulled to 1e-4 of its former distance:
// that node's distributed area is about 1e-8 of a typical node's.
inline SurfaceMesh tiny_patch_sphere(double r, int levels, int& centre) {
  SurfaceMesh mesh = make_icosphere(r, levels);
  centre = nearest_node(mesh.positions, Vec3(0.3, 0.2, 1.0).normalized() * r);
  const Vec3 p = mesh.positions.row(centre);
  std::vector<int> ring;
  for (int k = 0; k < mesh.triangle_count(); ++k)
    for (int e = 0; e < 3; ++e)
      if (mesh.triangles(k, e) == centre)
        for (int f = 0; f < 3; ++f)
          if (mesh.triangles(k, f) != centre) ring.push_back(mesh.triangles(k, f));
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  for (int j : ring) mesh.positions.row(j) = (p + 1e-4 * (mesh.positions.row(j).transpose() - p)).transpose();
  return mesh;
}

// A cube of side L, 12 cells per edge, graded geometrically so the cells at the centre of
// each face are 100 times smaller than those at its edges.
inline SurfaceMesh graded_cube(double L) {
  const int cells = 12, half = cells / 2;
  const double ratio = std::pow(100.0, 1.0 / (half - 1));  // width grows by this per cell
  std::vector<double> edge(half + 1, 0.0);  // grid lines from the centre outward, in [0, 1]
  double w = 1.0, total = 0.0;
  for (int k = 1; k <= half; ++k, w *= ratio) edge[k] = total += w;
  for (double& e : edge) e /= total;
  SurfaceMesh mesh = make_box(Vec3(L, L, L), cells, cells, cells);
  const double h = L / cells;
  for (int axis = 0; axis < 3; ++axis)
    remap_axis(mesh, axis, [&](double c) {
      const double g = std::abs(c) / h;  // in grid units from the centre: k or k + 0.5
      const int k = std::min(static_cast<int>(std::floor(g + 1e-9)), half);
      const double frac = g - k;
      const double e = k >= half ? 1.0 : edge[k] + frac * (edge[k + 1] - edge[k]);
      return std::copysign(0.5 * L * e, c);
    });
  return mesh;
}

// A latitude-longitude sphere with 12 segments (valence-12 poles), with one triangle at the
// equator split at its centroid (a valence-3 node, pushed onto the sphere).
inline SurfaceMesh valence_sphere(double r, int& v3, int& v12) {
  SurfaceMesh mesh = make_uv_sphere(r, 8, 12);
  v12 = nearest_node(mesh.positions, Vec3(0, 0, r));
  const int side = nearest_node(mesh.positions, Vec3(r, 0, 0));  // far from both poles
  int tri = -1;
  for (int k = 0; k < mesh.triangle_count() && tri < 0; ++k)
    for (int e = 0; e < 3; ++e)
      if (mesh.triangles(k, e) == side) tri = k;
  const Eigen::Vector3i t = mesh.triangles.row(tri);
  const Vec3 c = (mesh.positions.row(t[0]) + mesh.positions.row(t[1]) + mesh.positions.row(t[2])).transpose() / 3.0;
  const int n = mesh.node_count();
  mesh.positions.conservativeResize(n + 1, 3);
  mesh.positions.row(n) = (c.normalized() * r).transpose();
  v3 = n;
  const int nt = mesh.triangle_count();
  mesh.triangles.conservativeResize(nt + 2, 3);
  mesh.triangles.row(tri) << t[0], t[1], n;
  mesh.triangles.row(nt) << t[1], t[2], n;
  mesh.triangles.row(nt + 1) << t[2], t[0], n;
  return mesh;
}

// Valence (number of distinct neighbours) of every node.
inline std::vector<int> valences(const SurfaceMesh& mesh) {
  std::vector<std::vector<int>> nb(static_cast<size_t>(mesh.node_count()));
  for (int k = 0; k < mesh.triangle_count(); ++k)
    for (int e = 0; e < 3; ++e)
      for (int f = 0; f < 3; ++f)
        if (e != f) nb[mesh.triangles(k, e)].push_back(mesh.triangles(k, f));
  std::vector<int> v;
  for (auto& l : nb) {
    std::sort(l.begin(), l.end());
    v.push_back(static_cast<int>(std::unique(l.begin(), l.end()) - l.begin()));
  }
  return v;
}

}  // namespace vdm::hard
