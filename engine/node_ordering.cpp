#include "engine/node_ordering.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>

#include "engine/mesh_topology.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

// Breadth-first search over the unvisited piece of `start`; returns the last node reached.
// `level` (-1 = unvisited by this search) is restored to -1 for the nodes it touched.
int farthest(const SpMat& p, int start, std::vector<int>& level, std::vector<int>& queue) {
  const int* outer = p.outerIndexPtr();
  const int* inner = p.innerIndexPtr();
  queue.clear();
  queue.push_back(start);
  level[start] = 0;
  int last = start;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int u = queue[head];
    // The lowest-degree node of the deepest level (ties: lowest index).
    if (level[u] > level[last] ||
        (level[u] == level[last] && (outer[u + 1] - outer[u] < outer[last + 1] - outer[last] ||
                                     (outer[u + 1] - outer[u] == outer[last + 1] - outer[last] && u < last))))
      last = u;
    for (int k = outer[u]; k < outer[u + 1]; ++k) {
      const int v = inner[k];
      if (level[v] < 0) {
        level[v] = level[u] + 1;
        queue.push_back(v);
      }
    }
  }
  for (int u : queue) level[u] = -1;
  return last;
}

}  // namespace

std::vector<int> reverse_cuthill_mckee(const SpMat& p) {
  const int n = static_cast<int>(p.cols());
  const int* outer = p.outerIndexPtr();
  const int* inner = p.innerIndexPtr();
  auto degree = [&](int i) { return outer[i + 1] - outer[i]; };
  std::vector<int> order, level(n, -1), queue, nbr;
  order.reserve(n);
  std::vector<char> placed(n, 0);
  std::vector<int> by_degree(n);
  for (int i = 0; i < n; ++i) by_degree[i] = i;
  std::stable_sort(by_degree.begin(), by_degree.end(), [&](int a, int b) { return degree(a) < degree(b); });
  for (int seed : by_degree) {
    if (placed[seed]) continue;
    const int start = farthest(p, farthest(p, seed, level, queue), level, queue);
    // Cuthill-McKee from `start`.
    const size_t first = order.size();
    order.push_back(start);
    placed[start] = 1;
    for (size_t head = first; head < order.size(); ++head) {
      const int u = order[head];
      nbr.clear();
      for (int k = outer[u]; k < outer[u + 1]; ++k)
        if (!placed[inner[k]]) nbr.push_back(inner[k]);
      std::sort(nbr.begin(), nbr.end(), [&](int a, int b) { return degree(a) != degree(b) ? degree(a) < degree(b) : a < b; });
      for (int v : nbr) {
        placed[v] = 1;
        order.push_back(v);
      }
    }
  }
  std::reverse(order.begin(), order.end());
  return order;
}

int bandwidth(const SpMat& p, const std::vector<int>& new_to_old) {
  const int n = static_cast<int>(p.cols());
  std::vector<int> old_to_new(n);
  for (int i = 0; i < n; ++i) old_to_new[new_to_old.empty() ? i : new_to_old[i]] = i;
  int b = 0;
  for (int j = 0; j < n; ++j)
    for (int k = p.outerIndexPtr()[j]; k < p.outerIndexPtr()[j + 1]; ++k)
      b = std::max(b, std::abs(old_to_new[p.innerIndexPtr()[k]] - old_to_new[j]));
  return b;
}

std::vector<int> renumber_for_locality(SurfaceMesh& mesh) {
  const int n = mesh.node_count();
  const std::vector<int> order = reverse_cuthill_mckee(build_stiffness_pattern(n, unique_edges(mesh.triangles)).matrix);
  std::vector<int> new_of(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) new_of[size_t(order[size_t(i)])] = i;
  NodeMat positions(n, 3);
  for (int i = 0; i < n; ++i) positions.row(i) = mesh.positions.row(order[size_t(i)]);
  // Triangles by their smallest new node index, then the next ones (a total order: the
  // result does not depend on the sort's algorithm).
  const int t = mesh.triangle_count();
  std::vector<std::array<int, 3>> tris(static_cast<size_t>(t));
  for (int k = 0; k < t; ++k)
    for (int c = 0; c < 3; ++c) tris[size_t(k)][size_t(c)] = new_of[size_t(mesh.triangles(k, c))];
  auto key = [](const std::array<int, 3>& a) {
    std::array<int, 3> s = a;
    std::sort(s.begin(), s.end());
    return s;
  };
  std::sort(tris.begin(), tris.end(), [&](const std::array<int, 3>& a, const std::array<int, 3>& b) {
    const auto ka = key(a), kb = key(b);
    return ka != kb ? ka < kb : a < b;
  });
  for (int k = 0; k < t; ++k)
    for (int c = 0; c < 3; ++c) mesh.triangles(k, c) = tris[size_t(k)][size_t(c)];
  mesh.positions = std::move(positions);
  return order;
}

}  // namespace vdm
