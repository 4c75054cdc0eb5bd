#pragma once
// Each node's neighbours over the surface edges, with the edge that joins them: the rows of
// the stiffness pattern without their diagonal, for gathers that take the edge weights
// (AxisStiffness::weight, in edge order) row by row instead of scattering over the edges.
#include <array>
#include <vector>

namespace vdm {

struct NeighbourLists {
  struct Entry {
    int node;  // the neighbour j
    int edge;  // index of the edge (i, j) in the model's edge list
  };
  std::vector<int> begin;      // N + 1: node i's entries are [begin[i], begin[i + 1])
  std::vector<Entry> entries;  // 2 E, each node's in ascending neighbour order
  int reach = -1;              // the largest |i - j| over the edges (-1: not measured)
};

// The lists of `n` nodes joined by `edges` (each pair once, i != j).
NeighbourLists build_neighbour_lists(int n, const std::vector<std::array<int, 2>>& edges);

}  // namespace vdm
