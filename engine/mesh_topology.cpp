#include "engine/mesh_topology.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "engine/geometry.hpp"

namespace vdm {
namespace {

struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

MeshCheck fail(MeshProblem p, const std::string& msg) {
  MeshCheck c;
  c.problem = p;
  c.message = msg;
  return c;
}

std::string point_str(const NodeMat& x, int i) {
  std::ostringstream s;
  s << "(" << x(i, 0) << ", " << x(i, 1) << ", " << x(i, 2) << ")";
  return s.str();
}

}  // namespace

const char* to_string(MeshProblem p) {
  switch (p) {
    case MeshProblem::none: return "none";
    case MeshProblem::empty: return "empty mesh";
    case MeshProblem::bad_index: return "bad node index";
    case MeshProblem::non_finite: return "non-finite coordinate";
    case MeshProblem::degenerate_triangle: return "degenerate triangle";
    case MeshProblem::non_manifold_edge: return "non-manifold edge";
    case MeshProblem::open_boundary: return "open surface";
    case MeshProblem::inconsistent_orientation: return "inconsistent orientation";
    case MeshProblem::non_manifold_vertex: return "non-manifold vertex";
    case MeshProblem::multiple_components: return "several connected components";
    case MeshProblem::zero_volume: return "zero volume";
    case MeshProblem::self_intersection: return "self-intersection";
  }
  return "unknown";
}

// Every triangle side as (min, max), sorted: each undirected edge once per triangle using it.
static std::vector<std::array<int, 2>> sorted_edge_uses(const TriMat& tris) {
  std::vector<std::array<int, 2>> edges;
  edges.reserve(static_cast<size_t>(tris.rows()) * 3);
  for (Eigen::Index k = 0; k < tris.rows(); ++k)
    for (int e = 0; e < 3; ++e) {
      const int a = tris(k, e), b = tris(k, (e + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  return edges;
}

std::vector<std::array<int, 2>> unique_edges(const TriMat& tris) {
  std::vector<std::array<int, 2>> edges = sorted_edge_uses(tris);
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  // Each edge of a closed surface is used twice: without this the model would keep twice the
  // memory its edges need (1 MB more at 40k nodes).
  edges.shrink_to_fit();
  return edges;
}

bool is_closed(const TriMat& tris) {
  const std::vector<std::array<int, 2>> e = sorted_edge_uses(tris);
  for (size_t s = 0; s < e.size();) {
    size_t t = s;
    while (t < e.size() && e[t] == e[s]) ++t;
    if (t - s != 2) return false;
    s = t;
  }
  return !e.empty();
}

int drop_unreferenced_nodes(SurfaceMesh& mesh) {
  const int n = mesh.node_count();
  std::vector<int> remap(n, -1);
  for (Eigen::Index k = 0; k < mesh.triangles.rows(); ++k)
    for (int c = 0; c < 3; ++c) {
      const int i = mesh.triangles(k, c);
      if (i >= 0 && i < n) remap[i] = 0;
    }
  int next = 0;
  for (int i = 0; i < n; ++i)
    if (remap[i] == 0) remap[i] = next++;
  if (next == n) return 0;
  NodeMat kept(next, 3);
  for (int i = 0; i < n; ++i)
    if (remap[i] >= 0) kept.row(remap[i]) = mesh.positions.row(i);
  for (Eigen::Index k = 0; k < mesh.triangles.rows(); ++k)
    for (int c = 0; c < 3; ++c) {
      int& i = mesh.triangles(k, c);
      if (i >= 0 && i < n) i = remap[i];
    }
  mesh.positions = std::move(kept);
  return n - next;
}

MeshCheck check_and_orient_surface(SurfaceMesh& mesh) {
  const int n = mesh.node_count();
  const int t = mesh.triangle_count();
  if (n == 0 || t == 0) {
    std::ostringstream s;
    s << "the mesh has " << n << " nodes and " << t << " triangles; an organ needs a closed surface";
    return fail(MeshProblem::empty, s.str());
  }
  const NodeMat& x = mesh.positions;
  const TriMat& f = mesh.triangles;
  for (int k = 0; k < t; ++k)
    for (int c = 0; c < 3; ++c)
      if (f(k, c) < 0 || f(k, c) >= n) {
        std::ostringstream s;
        s << "triangle " << k << " refers to node " << f(k, c) << " but there are " << n << " nodes";
        return fail(MeshProblem::bad_index, s.str());
      }
  for (int i = 0; i < n; ++i)
    if (!x.row(i).allFinite()) {
      std::ostringstream s;
      s << "node " << i << " has a non-finite coordinate " << point_str(x, i);
      return fail(MeshProblem::non_finite, s.str());
    }

  // Zero-area triangles, relative to the size of the whole mesh.
  const double diag = (x.colwise().maxCoeff() - x.colwise().minCoeff()).norm();
  const double min_area = 1e-14 * diag * diag;
  for (int k = 0; k < t; ++k) {
    const Vec3 a = x.row(f(k, 0)), b = x.row(f(k, 1)), c = x.row(f(k, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (f(k, 0) == f(k, 1) || f(k, 1) == f(k, 2) || f(k, 0) == f(k, 2) || !(area > min_area)) {
      std::ostringstream s;
      s << "triangle " << k << " (nodes " << f(k, 0) << ", " << f(k, 1) << ", " << f(k, 2)
        << ") has zero area";
      return fail(MeshProblem::degenerate_triangle, s.str());
    }
  }

  // Directed half-edges: each undirected edge of a closed oriented manifold is used exactly
  // twice, once in each direction.
  struct HalfEdge {
    int lo, hi, tri;
    bool forward;  // stored as lo->hi
  };
  std::vector<HalfEdge> half;
  half.reserve(static_cast<size_t>(t) * 3);
  for (int k = 0; k < t; ++k)
    for (int e = 0; e < 3; ++e) {
      const int a = f(k, e), b = f(k, (e + 1) % 3);
      half.push_back({std::min(a, b), std::max(a, b), k, a < b});
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& p, const HalfEdge& q) {
    return p.lo != q.lo ? p.lo < q.lo : (p.hi != q.hi ? p.hi < q.hi : p.tri < q.tri);
  });
  // Report the worst class first: non-manifold, then holes, then orientation.
  size_t open_at = half.size(), flip_at = half.size();
  for (size_t s = 0; s < half.size();) {
    size_t e = s;
    while (e < half.size() && half[e].lo == half[s].lo && half[e].hi == half[s].hi) ++e;
    const size_t uses = e - s;
    if (uses > 2) {
      std::ostringstream m;
      m << "edge (" << half[s].lo << ", " << half[s].hi << ") is shared by " << uses
        << " triangles (" << half[s].tri << ", " << half[s + 1].tri << ", " << half[s + 2].tri
        << "); a surface edge must have exactly two";
      return fail(MeshProblem::non_manifold_edge, m.str());
    }
    if (uses == 1 && open_at == half.size()) open_at = s;
    if (uses == 2 && half[s].forward == half[s + 1].forward && flip_at == half.size()) flip_at = s;
    s = e;
  }
  if (open_at < half.size()) {
    const HalfEdge& h = half[open_at];
    std::ostringstream m;
    m << "edge (" << h.lo << ", " << h.hi << ") of triangle " << h.tri
      << " belongs to no other triangle: the surface has a hole at " << point_str(x, h.lo);
    return fail(MeshProblem::open_boundary, m.str());
  }
  if (flip_at < half.size()) {
    const HalfEdge& h = half[flip_at];
    std::ostringstream m;
    m << "triangles " << h.tri << " and " << half[flip_at + 1].tri
      << " traverse their shared edge (" << h.lo << ", " << h.hi
      << ") in the same direction: orientation is inconsistent";
    return fail(MeshProblem::inconsistent_orientation, m.str());
  }

  // Each node's one-ring must be a single fan (otherwise two sheets touch at a point).
  {
    std::vector<int> first(n + 1, 0);
    for (int k = 0; k < t; ++k)
      for (int c = 0; c < 3; ++c) ++first[f(k, c) + 1];
    for (int i = 0; i < n; ++i) first[i + 1] += first[i];
    std::vector<int> fill(first.begin(), first.end() - 1), around(static_cast<size_t>(t) * 3);
    for (int k = 0; k < t; ++k)
      for (int c = 0; c < 3; ++c) around[fill[f(k, c)]++] = k;
    for (int i = 0; i < n; ++i) {
      const int count = first[i + 1] - first[i];
      if (count == 0) continue;
      // Walk the fan: from one triangle, go to the one sharing the outgoing edge.
      int visited = 0;
      int k = around[first[i]];
      do {
        int c = 0;
        while (f(k, c) != i) ++c;
        const int next_node = f(k, (c + 2) % 3);  // edge (next_node -> i) in k; neighbour has (i -> next_node)
        int next_tri = -1;
        for (int s = first[i]; s < first[i + 1]; ++s) {
          const int q = around[s];
          for (int d = 0; d < 3; ++d)
            if (f(q, d) == i && f(q, (d + 1) % 3) == next_node) next_tri = q;
        }
        ++visited;
        k = next_tri;
      } while (k != around[first[i]] && k >= 0 && visited <= count);
      if (visited != count) {
        std::ostringstream m;
        m << "node " << i << " at " << point_str(x, i) << " joins " << count
          << " triangles that do not form a single fan (two sheets touch there)";
        return fail(MeshProblem::non_manifold_vertex, m.str());
      }
    }
  }

  // Connected components over triangles.
  DisjointSets sets(n);
  std::vector<char> used(n, 0);
  for (int k = 0; k < t; ++k) {
    sets.unite(f(k, 0), f(k, 1));
    sets.unite(f(k, 1), f(k, 2));
    used[f(k, 0)] = used[f(k, 1)] = used[f(k, 2)] = 1;
  }
  int components = 0;
  for (int i = 0; i < n; ++i)
    if (used[i] && sets.find(i) == i) ++components;
  if (components > 1) {
    std::ostringstream m;
    m << "the surface has " << components << " separate connected pieces; one organ must be one piece";
    return fail(MeshProblem::multiple_components, m.str());
  }

  // Orientation: outward means positive enclosed volume.
  const Vec3 origin = x.colwise().mean();
  const double v = enclosed_volume(x, f, origin);
  const double scale = diag * diag * diag;
  if (!(std::abs(v) > 1e-12 * scale)) {
    return fail(MeshProblem::zero_volume, "the closed surface encloses no volume");
  }
  MeshCheck ok;
  if (v < 0) {
    for (int k = 0; k < t; ++k) std::swap(mesh.triangles(k, 1), mesh.triangles(k, 2));
    ok.flipped = true;
  }
  return ok;
}

}  // namespace vdm
