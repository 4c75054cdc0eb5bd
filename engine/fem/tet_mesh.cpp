#include "engine/fem/tet_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "engine/shapes.hpp"

namespace vdm::fem {

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

TetMesh make_box_tets(const Vec3& size, int nx, int ny, int nz, const Vec3& center) {
  TetMesh out;
  out.surface = make_box(size, nx, ny, nz, center);
  out.surface_nodes = out.surface.node_count();
  const std::array<int, 3> n = {nx, ny, nz};
  const Vec3 lo = center - size / 2;
  // Doubled lattice: corners at even coordinates, face and cell centres at odd ones.
  std::map<std::array<int, 3>, int> index;
  std::vector<Vec3> nodes;
  for (int i = 0; i < out.surface_nodes; ++i) {
    std::array<int, 3> g{};
    for (int d = 0; d < 3; ++d)
      g[d] = static_cast<int>(std::lround((out.surface.positions(i, d) - lo[d]) / size[d] * 2 * n[d]));
    index.emplace(g, i);
    nodes.push_back(out.surface.positions.row(i).transpose());
  }
  auto node = [&](const std::array<int, 3>& g) {
    auto it = index.find(g);
    if (it != index.end()) return it->second;
    Vec3 p;
    for (int d = 0; d < 3; ++d) p[d] = lo[d] + size[d] * g[d] / (2.0 * n[d]);
    nodes.push_back(p);
    const int id = static_cast<int>(nodes.size()) - 1;
    index.emplace(g, id);
    return id;
  };
  std::vector<std::array<int, 4>> tets;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const std::array<int, 3> c = {2 * i + 1, 2 * j + 1, 2 * k + 1};
        const int centre = node(c);
        for (int axis = 0; axis < 3; ++axis) {
          const int u = (axis + 1) % 3, v = (axis + 2) % 3;
          for (int side = -1; side <= 1; side += 2) {
            std::array<int, 3> f = c;
            f[axis] += side;
            const int face = node(f);
            const int du[4] = {-1, 1, 1, -1}, dv[4] = {-1, -1, 1, 1};
            int corner[4];
            for (int q = 0; q < 4; ++q) {
              std::array<int, 3> g = f;
              g[u] += du[q];
              g[v] += dv[q];
              corner[q] = node(g);
            }
            for (int q = 0; q < 4; ++q) tets.push_back({corner[q], corner[(q + 1) % 4], face, centre});
          }
        }
      }
  out.positions.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (size_t i = 0; i < nodes.size(); ++i) out.positions.row(static_cast<Eigen::Index>(i)) = nodes[i];
  out.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t t = 0; t < tets.size(); ++t) {
    std::array<int, 4> e = tets[t];
    const Vec3 a = nodes[e[0]], b = nodes[e[1]], c = nodes[e[2]], d = nodes[e[3]];
    if (tet_volume(a, b, c, d) < 0) std::swap(e[0], e[1]);
    for (int q = 0; q < 4; ++q) out.tets(static_cast<Eigen::Index>(t), q) = e[q];
  }
  return out;
}

bool check_tet_mesh(TetMesh& mesh, std::string& error) {
  const int n = mesh.node_count();
  if (mesh.tet_count() == 0) return error = "the tet mesh has no tetrahedra", false;
  if (mesh.surface_nodes <= 0 || mesh.surface_nodes > n)
    return error = "the tet mesh's surface node count is out of range", false;
  if (!mesh.positions.allFinite()) return error = "the tet mesh has a non-finite coordinate", false;
  // Boundary faces: faces of exactly one tet, oriented outward.
  std::map<std::array<int, 3>, std::pair<int, std::array<int, 3>>> faces;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    std::array<int, 4> e;
    for (int q = 0; q < 4; ++q) {
      e[q] = mesh.tets(t, q);
      if (e[q] < 0 || e[q] >= n) return error = "tet " + std::to_string(t) + " has a node index out of range", false;
    }
    const double v = tet_volume(mesh.positions.row(e[0]), mesh.positions.row(e[1]), mesh.positions.row(e[2]),
                                mesh.positions.row(e[3]));
    if (!(v > 0)) return error = "tet " + std::to_string(t) + " is inverted or flat (volume " + std::to_string(v) + ")", false;
    // Outward faces of a positive tet (0,1,2,3): (0,2,1), (0,1,3), (1,2,3), (0,3,2).
    const int fq[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
    for (const auto& f : fq) {
      std::array<int, 3> tri = {e[f[0]], e[f[1]], e[f[2]]};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto it = faces.find(key);
      if (it == faces.end()) faces.emplace(key, std::make_pair(1, tri));
      else ++it->second.first;
    }
  }
  std::vector<std::array<int, 3>> boundary;
  for (const auto& [key, val] : faces) {
    if (val.first > 2) return error = "a face is shared by more than two tets", false;
    if (val.first == 1) boundary.push_back(val.second);
  }
  for (const auto& tri : boundary)
    for (int c : tri)
      if (c >= mesh.surface_nodes)
        return error = "node " + std::to_string(c) + " lies on the boundary but is not among the surface nodes", false;
  if (mesh.surface.triangles.rows() == 0) {
    mesh.surface.triangles.resize(static_cast<Eigen::Index>(boundary.size()), 3);
    for (size_t k = 0; k < boundary.size(); ++k)
      for (int c = 0; c < 3; ++c) mesh.surface.triangles(static_cast<Eigen::Index>(k), c) = boundary[k][c];
  } else if (static_cast<size_t>(mesh.surface.triangles.rows()) != boundary.size()) {
    return error = "the tets' boundary has " + std::to_string(boundary.size()) + " triangles, the surface " +
                   std::to_string(mesh.surface.triangles.rows()),
           false;
  }
  mesh.surface.positions = mesh.positions.topRows(mesh.surface_nodes);
  return true;
}

}  // namespace vdm::fem
