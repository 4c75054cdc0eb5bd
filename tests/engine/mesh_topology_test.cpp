#include <gtest/gtest.h>

#include <cmath>

#include "engine/mesh_topology.hpp"
#include "engine/shapes.hpp"

namespace vdm {
namespace {

SurfaceMesh tetra(const Vec3& offset = Vec3::Zero()) {
  SurfaceMesh m;
  m.positions.resize(4, 3);
  m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.positions.rowwise() += offset.transpose();
  m.triangles.resize(4, 3);
  m.triangles << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return m;
}

SurfaceMesh join(const SurfaceMesh& a, const SurfaceMesh& b) {
  SurfaceMesh m;
  m.positions.resize(a.node_count() + b.node_count(), 3);
  m.positions << a.positions, b.positions;
  m.triangles.resize(a.triangle_count() + b.triangle_count(), 3);
  m.triangles << a.triangles, (b.triangles.array() + a.node_count()).matrix();
  return m;
}

MeshProblem problem_of(SurfaceMesh m) { return check_and_orient_surface(m).problem; }

TEST(MeshTopology, TetraIsValidAndOutward) {
  SurfaceMesh m = tetra();
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_TRUE(c.ok()) << c.message;
  EXPECT_FALSE(c.flipped);
  EXPECT_EQ(unique_edges(m.triangles).size(), 6u);
}

TEST(MeshTopology, InwardSurfaceIsFlippedOutward) {
  SurfaceMesh m = make_box(Vec3(1, 1, 1), 2, 2, 2);
  for (int k = 0; k < m.triangle_count(); ++k) std::swap(m.triangles(k, 1), m.triangles(k, 2));
  const MeshCheck c = check_and_orient_surface(m);
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_TRUE(c.flipped);
  EXPECT_EQ(m.triangles, make_box(Vec3(1, 1, 1), 2, 2, 2).triangles);
}

TEST(MeshTopology, EmptyMesh) {
  SurfaceMesh m;
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::empty);
  EXPECT_NE(c.message.find("0 nodes"), std::string::npos) << c.message;
}

TEST(MeshTopology, BadIndexNamesTriangle) {
  SurfaceMesh m = tetra();
  m.triangles(2, 1) = 7;
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::bad_index);
  EXPECT_NE(c.message.find("triangle 2"), std::string::npos) << c.message;
}

TEST(MeshTopology, NonFiniteNamesNode) {
  SurfaceMesh m = tetra();
  m.positions(3, 1) = std::nan("");
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::non_finite);
  EXPECT_NE(c.message.find("node 3"), std::string::npos) << c.message;
}

TEST(MeshTopology, ZeroAreaTriangleIsNamed) {
  SurfaceMesh m = make_box(Vec3(1, 1, 1), 1, 1, 1);
  // Put triangle 5's third node on the segment between its first two: collinear, zero area.
  const int a = m.triangles(5, 0), b = m.triangles(5, 1), c = m.triangles(5, 2);
  m.positions.row(c) = 0.5 * (m.positions.row(a) + m.positions.row(b));
  const MeshCheck r = check_and_orient_surface(m);
  EXPECT_EQ(r.problem, MeshProblem::degenerate_triangle);
  EXPECT_NE(r.message.find("zero area"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("triangle "), std::string::npos) << r.message;
}

TEST(MeshTopology, RepeatedNodeIsDegenerate) {
  SurfaceMesh m = tetra();
  m.triangles(1, 2) = m.triangles(1, 0);
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::degenerate_triangle);
  EXPECT_NE(c.message.find("triangle 1"), std::string::npos) << c.message;
}

TEST(MeshTopology, HoleIsOpenBoundary) {
  SurfaceMesh m = make_box(Vec3(1, 1, 1), 2, 2, 2);
  m.triangles.conservativeResize(m.triangle_count() - 1, 3);
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::open_boundary);
  EXPECT_NE(c.message.find("hole"), std::string::npos) << c.message;
}

TEST(MeshTopology, FinEdgeIsNonManifold) {
  // A second tetra glued to the first along edge (1, 2) only: that edge has 4 triangles.
  SurfaceMesh a = tetra();
  SurfaceMesh m;
  m.positions.resize(6, 3);
  m.positions << a.positions, 1, 1, 1, 2, 2, -1;
  m.triangles.resize(8, 3);
  m.triangles << a.triangles, 1, 4, 2, 1, 5, 4, 2, 4, 5, 1, 2, 5;
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::non_manifold_edge);
  EXPECT_NE(c.message.find("edge (1, 2)"), std::string::npos) << c.message;
}

TEST(MeshTopology, OneFlippedTriangleIsInconsistent) {
  SurfaceMesh m = make_box(Vec3(1, 1, 1), 2, 2, 2);
  std::swap(m.triangles(7, 0), m.triangles(7, 1));
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::inconsistent_orientation);
  EXPECT_NE(c.message.find("triangles"), std::string::npos) << c.message;
}

TEST(MeshTopology, TwoTetrasTouchingAtANodeAreNonManifoldVertex) {
  SurfaceMesh a = tetra(), b = tetra(Vec3(1, 0, 0));  // b's node 0 sits on a's node 1
  SurfaceMesh m = join(a, b);
  for (int k = 4; k < 8; ++k)
    for (int c = 0; c < 3; ++c)
      if (m.triangles(k, c) == 4) m.triangles(k, c) = 1;  // weld the shared point
  const MeshCheck c = check_and_orient_surface(m);
  EXPECT_EQ(c.problem, MeshProblem::non_manifold_vertex);
  EXPECT_NE(c.message.find("node 1"), std::string::npos) << c.message;
}

TEST(MeshTopology, TwoSeparatePiecesAreRejected) {
  const MeshCheck c = [] {
    SurfaceMesh m = join(tetra(), tetra(Vec3(5, 0, 0)));
    return check_and_orient_surface(m);
  }();
  EXPECT_EQ(c.problem, MeshProblem::multiple_components);
  EXPECT_NE(c.message.find("2 separate"), std::string::npos) << c.message;
}

TEST(MeshTopology, FlatDoubleSidedSheetHasZeroVolume) {
  SurfaceMesh m;
  m.positions.resize(3, 3);
  m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 0, 2, 1;
  EXPECT_EQ(problem_of(m), MeshProblem::zero_volume);
}

TEST(MeshTopology, DropUnreferencedNodes) {
  SurfaceMesh m = tetra();
  m.positions.conservativeResize(6, 3);
  m.positions.row(4) << 9, 9, 9;
  m.positions.row(5) << 8, 8, 8;
  // Move node 3 to the end so renumbering is exercised.
  m.positions.row(5) = m.positions.row(3);
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      if (m.triangles(k, c) == 3) m.triangles(k, c) = 5;
  EXPECT_EQ(drop_unreferenced_nodes(m), 2);
  EXPECT_EQ(m.node_count(), 4);
  EXPECT_TRUE(check_and_orient_surface(m).ok());
  EXPECT_EQ(m.positions.row(3), tetra().positions.row(3));
}

}  // namespace
}  // namespace vdm
