#include "engine/shapes.hpp"

#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace vdm {
namespace {

struct MeshBuilder {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 3>> tris;
  int add(const Vec3& p) {
    nodes.push_back(p);
    return static_cast<int>(nodes.size()) - 1;
  }
  // Adds triangle (a, b, c), flipped if needed so its normal points along `outward`.
  void add_tri(int a, int b, int c, const Vec3& outward) {
    const Vec3 n = (nodes[b] - nodes[a]).cross(nodes[c] - nodes[a]);
    if (n.dot(outward) >= 0) tris.push_back({a, b, c});
    else tris.push_back({a, c, b});
  }
  SurfaceMesh build() const {
    SurfaceMesh m;
    m.positions.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    for (size_t i = 0; i < nodes.size(); ++i) m.positions.row(static_cast<Eigen::Index>(i)) = nodes[i];
    m.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
    for (size_t k = 0; k < tris.size(); ++k)
      for (int c = 0; c < 3; ++c) m.triangles(static_cast<Eigen::Index>(k), c) = tris[k][c];
    return m;
  }
};

}  // namespace

SurfaceMesh make_box(const Vec3& size, int nx, int ny, int nz, const Vec3& center) {
  const std::array<int, 3> n = {nx, ny, nz};
  MeshBuilder b;
  std::map<std::array<int, 3>, int> grid;  // surface lattice node -> index
  auto lattice = [&](std::array<int, 3> g) {
    auto it = grid.find(g);
    if (it != grid.end()) return it->second;
    Vec3 p;
    for (int d = 0; d < 3; ++d) p[d] = center[d] + size[d] * (double(g[d]) / n[d] - 0.5);
    const int id = b.add(p);
    grid.emplace(g, id);
    return id;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      Vec3 outward = Vec3::Zero();
      outward[axis] = side ? 1.0 : -1.0;
      for (int i = 0; i < n[u]; ++i)
        for (int j = 0; j < n[v]; ++j) {
          std::array<int, 3> g{};
          g[axis] = side ? n[axis] : 0;
          int corner[4];
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            g[u] = i + di[c];
            g[v] = j + dj[c];
            corner[c] = lattice(g);
          }
          Vec3 mid = Vec3::Zero();
          for (int c = 0; c < 4; ++c) mid += b.nodes[corner[c]] / 4.0;
          const int m = b.add(mid);
          for (int c = 0; c < 4; ++c) b.add_tri(corner[c], corner[(c + 1) % 4], m, outward);
        }
    }
  }
  return b.build();
}

SurfaceMesh make_icosphere(double radius, int levels, const Vec3& center) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                       {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (auto& q : p) q.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int c) {
      const auto key = std::make_pair(std::min(a, c), std::max(a, c));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[a] + p[c]).normalized());
      const int id = static_cast<int>(p.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> g;
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), bb = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, c});
      g.push_back({tri[1], bb, a});
      g.push_back({tri[2], c, bb});
      g.push_back({a, bb, c});
    }
    f.swap(g);
  }
  MeshBuilder b;
  for (const auto& q : p) b.add(center + radius * q);
  for (const auto& tri : f) {
    const Vec3 c = (p[tri[0]] + p[tri[1]] + p[tri[2]]);
    b.add_tri(tri[0], tri[1], tri[2], c);
  }
  return b.build();
}

SurfaceMesh make_uv_sphere(double radius, int rings, int segments, const Vec3& center) {
  MeshBuilder b;
  const double pi = 3.14159265358979323846;
  const int top = b.add(center + Vec3(0, 0, radius));
  std::vector<std::vector<int>> ring(rings - 1, std::vector<int>(segments));
  for (int r = 1; r < rings; ++r) {
    const double th = pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double ph = 2 * pi * s / segments;
      ring[r - 1][s] = b.add(center + radius * Vec3(std::sin(th) * std::cos(ph),
                                                    std::sin(th) * std::sin(ph), std::cos(th)));
    }
  }
  const int bottom = b.add(center - Vec3(0, 0, radius));
  for (int s = 0; s < segments; ++s) {
    const int s1 = (s + 1) % segments;
    b.add_tri(top, ring[0][s], ring[0][s1], Vec3(0, 0, 1));
    for (int r = 0; r + 1 < rings - 1; ++r) {
      const Vec3 out = (b.nodes[ring[r][s]] + b.nodes[ring[r + 1][s1]]) / 2 - center;
      b.add_tri(ring[r][s], ring[r + 1][s], ring[r + 1][s1], out);
      b.add_tri(ring[r][s], ring[r + 1][s1], ring[r][s1], out);
    }
    b.add_tri(bottom, ring[rings - 2][s1], ring[rings - 2][s], Vec3(0, 0, -1));
  }
  return b.build();
}

}  // namespace vdm
