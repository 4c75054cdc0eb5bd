#include "engine/neighbour_lists.hpp"

#include <algorithm>
#include <cstdlib>

namespace vdm {

NeighbourLists build_neighbour_lists(int n, const std::vector<std::array<int, 2>>& edges) {
  NeighbourLists l;
  l.reach = 0;
  // Count each node's edges, then place them (counting sort by node).
  l.begin.assign(size_t(n) + 1, 0);
  for (const auto& e : edges) {
    ++l.begin[size_t(e[0]) + 1];
    ++l.begin[size_t(e[1]) + 1];
  }
  for (int i = 0; i < n; ++i) l.begin[size_t(i) + 1] += l.begin[size_t(i)];
  l.entries.resize(2 * edges.size());
  std::vector<int> next(l.begin.begin(), l.begin.end() - 1);
  for (size_t k = 0; k < edges.size(); ++k) {
    const int i = edges[k][0], j = edges[k][1];
    l.entries[size_t(next[size_t(i)]++)] = {j, int(k)};
    l.entries[size_t(next[size_t(j)]++)] = {i, int(k)};
    l.reach = std::max(l.reach, std::abs(i - j));
  }
  // Ascending neighbours: the pattern's order (already so for edges sorted as unique_edges
  // gives them).
  for (int i = 0; i < n; ++i)
    std::sort(l.entries.begin() + l.begin[size_t(i)], l.entries.begin() + l.begin[size_t(i) + 1],
              [](const NeighbourLists::Entry& a, const NeighbourLists::Entry& b) { return a.node < b.node; });
  return l;
}

}  // namespace vdm
