// Reverse Cuthill-McKee (engine/node_ordering): a permutation that keeps neighbours close.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "engine/mesh_topology.hpp"
#include "engine/node_ordering.hpp"
#include "engine/shapes.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

// The stiffness pattern of `mesh` with its nodes renumbered by `old_to_new`.
SpMat pattern_of(const SurfaceMesh& mesh, const std::vector<int>& old_to_new) {
  std::vector<std::array<int, 2>> edges;
  for (int k = 0; k < mesh.triangle_count(); ++k)
    for (int c = 0; c < 3; ++c) {
      int i = old_to_new[mesh.triangles(k, c)], j = old_to_new[mesh.triangles(k, (c + 1) % 3)];
      if (i > j) std::swap(i, j);
      edges.push_back({i, j});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return build_stiffness_pattern(mesh.node_count(), edges).matrix;
}

bool is_permutation_of_n(std::vector<int> p, int n) {
  if (static_cast<int>(p.size()) != n) return false;
  std::sort(p.begin(), p.end());
  for (int i = 0; i < n; ++i)
    if (p[i] != i) return false;
  return true;
}

TEST(NodeOrdering, ShuffledSphereGetsANarrowBand) {
  const SurfaceMesh mesh = make_icosphere(1.0, 4);  // 2562 nodes
  const int n = mesh.node_count();
  std::vector<int> shuffle(n);
  std::iota(shuffle.begin(), shuffle.end(), 0);
  std::mt19937 rng(7);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  const SpMat p = pattern_of(mesh, shuffle);
  const std::vector<int> order = reverse_cuthill_mckee(p);
  ASSERT_TRUE(is_permutation_of_n(order, n));
  // A sphere of n nodes: a band of order sqrt(n) (the nodes of one latitude ring), against
  // about n for a random numbering.
  const int shuffled = bandwidth(p), ordered = bandwidth(p, order);
  EXPECT_GT(shuffled, n / 2);
  EXPECT_LT(ordered, 6 * static_cast<int>(std::sqrt(double(n))));
  // Same pattern, same ordering: deterministic.
  EXPECT_EQ(reverse_cuthill_mckee(p), order);
}

TEST(NodeOrdering, SeveralPiecesAreAllOrdered) {
  // Two separate spheres in one pattern: every node is placed once.
  const SurfaceMesh a = make_icosphere(1.0, 2);
  const int na = a.node_count();
  std::vector<std::array<int, 2>> edges;
  for (int piece = 0; piece < 2; ++piece)
    for (int k = 0; k < a.triangle_count(); ++k)
      for (int c = 0; c < 3; ++c) {
        int i = a.triangles(k, c) + piece * na, j = a.triangles(k, (c + 1) % 3) + piece * na;
        if (i > j) std::swap(i, j);
        edges.push_back({i, j});
      }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const SpMat p = build_stiffness_pattern(2 * na, edges).matrix;
  const std::vector<int> order = reverse_cuthill_mckee(p);
  EXPECT_TRUE(is_permutation_of_n(order, 2 * na));
  EXPECT_LT(bandwidth(p, order), na);  // a piece's nodes stay together
}

}  // namespace
}  // namespace vdm
