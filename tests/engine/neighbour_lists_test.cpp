// The neighbour lists against the stiffness pattern they mirror.
#include <gtest/gtest.h>
#include <algorithm>
#include <cstdlib>

#include "engine/mesh_topology.hpp"
#include "engine/neighbour_lists.hpp"
#include "engine/shapes.hpp"
#include "engine/sparse.hpp"

namespace vdm {
namespace {

// Every node's entries are the pattern's column without its diagonal, in its order, and
// each names the edge that joins the two nodes; the lists know how far apart in index two
// neighbours are at most.
TEST(NeighbourLists, ArePatternRowsWithoutTheDiagonalWithTheirEdges) {
  const SurfaceMesh mesh = make_icosphere(1.0, 2);
  std::vector<std::array<int, 2>> edges = unique_edges(mesh.triangles);
  std::reverse(edges.begin(), edges.end());  // any edge order: the lists still ascend
  const int n = mesh.node_count();
  const StiffnessPattern p = build_stiffness_pattern(n, edges);
  const NeighbourLists l = build_neighbour_lists(n, edges);
  ASSERT_EQ(l.begin.size(), size_t(n) + 1);
  ASSERT_EQ(l.entries.size(), 2 * edges.size());
  const int* outer = p.matrix.outerIndexPtr();
  const int* inner = p.matrix.innerIndexPtr();
  int reach = 0;  // the largest |i - j| over the edges
  for (const auto& e : edges) reach = std::max(reach, std::abs(e[0] - e[1]));
  EXPECT_EQ(l.reach, reach);
  EXPECT_GT(reach, 0);
  for (int i = 0; i < n; ++i) {
    std::vector<int> column;
    for (int k = outer[i]; k < outer[i + 1]; ++k)
      if (inner[k] != i) column.push_back(inner[k]);
    ASSERT_EQ(size_t(l.begin[i + 1] - l.begin[i]), column.size()) << "node " << i;
    for (size_t k = 0; k < column.size(); ++k) {
      const NeighbourLists::Entry e = l.entries[size_t(l.begin[i]) + k];
      EXPECT_EQ(e.node, column[k]) << "node " << i;
      const std::array<int, 2> edge = edges[size_t(e.edge)];
      EXPECT_TRUE((edge[0] == i && edge[1] == e.node) || (edge[1] == i && edge[0] == e.node)) << "node " << i;
    }
  }
}

}  // namespace
}  // namespace vdm
