// Reverse Cuthill-McKee (engine/node_ordering): a permutation that keeps neighbours close.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include "engine/geometry.hpp"
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

TEST(NodeOrdering, RenumberedMeshIsTheSameSurfaceInLocalityOrder) {
  // An icosphere with its nodes shuffled, renumbered: the same oriented triangles in space,
  // the same volume, neighbours close in index, triangles in order of their nodes.
  SurfaceMesh mesh = make_icosphere(1.0, 4);
  const int n = mesh.node_count();
  std::vector<int> shuffle(n);
  std::iota(shuffle.begin(), shuffle.end(), 0);
  std::mt19937 rng(11);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  SurfaceMesh shuffled = mesh;
  for (int i = 0; i < n; ++i) shuffled.positions.row(shuffle[i]) = mesh.positions.row(i);
  for (int k = 0; k < mesh.triangle_count(); ++k)
    for (int c = 0; c < 3; ++c) shuffled.triangles(k, c) = shuffle[mesh.triangles(k, c)];
  SurfaceMesh renumbered = shuffled;
  const std::vector<int> order = renumber_for_locality(renumbered);
  ASSERT_TRUE(is_permutation_of_n(order, n));
  ASSERT_EQ(renumbered.triangle_count(), mesh.triangle_count());
  for (int i = 0; i < n; ++i) ASSERT_EQ(renumbered.positions.row(i), shuffled.positions.row(order[i]));
  // Oriented triangles as node triples of the shuffled numbering, each rotated to start at
  // its smallest node (a rotation keeps the orientation; a flip would not match).
  auto oriented = [](int a, int b, int c) {
    std::array<int, 3> t = {a, b, c};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    return t;
  };
  std::set<std::array<int, 3>> before, after;
  for (int k = 0; k < mesh.triangle_count(); ++k) {
    before.insert(oriented(shuffled.triangles(k, 0), shuffled.triangles(k, 1), shuffled.triangles(k, 2)));
    after.insert(oriented(order[renumbered.triangles(k, 0)], order[renumbered.triangles(k, 1)],
                          order[renumbered.triangles(k, 2)]));
  }
  EXPECT_EQ(before, after);
  const Vec3 origin = Vec3::Zero();
  const double volume = enclosed_volume(shuffled.positions, shuffled.triangles, origin);
  EXPECT_NEAR(enclosed_volume(renumbered.positions, renumbered.triangles, origin), volume, 1e-13 * volume);  // summation order
  // Edges span a band of order sqrt(n); the shuffled numbering spans about n.
  std::vector<int> identity(n);
  std::iota(identity.begin(), identity.end(), 0);
  EXPECT_GT(bandwidth(pattern_of(shuffled, identity)), n / 2);
  EXPECT_LT(bandwidth(pattern_of(renumbered, identity)), 6 * static_cast<int>(std::sqrt(double(n))));
  // Triangles in order of their smallest node.
  for (int k = 1; k < renumbered.triangle_count(); ++k)
    EXPECT_LE(renumbered.triangles.row(k - 1).minCoeff(), renumbered.triangles.row(k).minCoeff());
}

}  // namespace
}  // namespace vdm
