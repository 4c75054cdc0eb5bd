#include "engine/node_ordering.hpp"

#include <algorithm>
#include <cstdlib>

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

}  // namespace vdm
