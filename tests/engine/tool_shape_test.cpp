// Instrument collision shapes: convex hulls and the signed distances of capsules, cylinders
// with rounded tips, boxes and convex polytopes, against analytic values and each other.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include <random>

#include "engine/contact.hpp"
#include "engine/convex_hull.hpp"
#include "engine/shapes.hpp"
#include "engine/tool_shape.hpp"

namespace vdm {
namespace {

std::vector<Vec3> box_corners(const Vec3& h) {
  std::vector<Vec3> p;
  for (int k = 0; k < 8; ++k) p.emplace_back((k & 1 ? 1 : -1) * h.x(), (k & 2 ? 1 : -1) * h.y(), (k & 4 ? 1 : -1) * h.z());
  return p;
}

TEST(ConvexHull, BoxCornersAndInteriorPoints) {
  const Vec3 h(0.01, 0.02, 0.03);
  std::vector<Vec3> pts = box_corners(h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 200; ++k) pts.emplace_back(u(rng) * h.x(), u(rng) * h.y(), u(rng) * h.z());
  ConvexHull hull;
  std::string error;
  ASSERT_TRUE(convex_hull(pts, hull, error)) << error;
  EXPECT_EQ(hull.vertices.size(), 8u);
  EXPECT_EQ(hull.triangles.size(), 12u);
  // Closed and outward: the divergence theorem gives the box's volume.
  double volume = 0;
  for (const auto& t : hull.triangles)
    volume += hull.vertices[t[0]].dot(hull.vertices[t[1]].cross(hull.vertices[t[2]])) / 6.0;
  EXPECT_NEAR(volume, 8 * h.prod(), 1e-15);
  EXPECT_NEAR(hull.inradius, h.minCoeff(), 1e-12);
}

TEST(ConvexHull, FinelyTessellatedCylinderGivesAClosedConvexHull) {
  // Many nearly coplanar points (a CAD-like cylinder: 720 around, 3 rings) plus the axis ends.
  std::vector<Vec3> pts;
  for (int ring = 0; ring < 3; ++ring)
    for (int k = 0; k < 720; ++k) {
      const double a = 2 * 3.14159265358979323846 * k / 720;
      pts.emplace_back(0.003 * std::cos(a), 0.003 * std::sin(a), 0.01 * ring);
    }
  pts.emplace_back(0, 0, 0);
  pts.emplace_back(0, 0, 0.02);
  ConvexHull h;
  std::string error;
  ASSERT_TRUE(convex_hull(pts, h, error)) << error;
  // Closed: Euler's formula for a sphere-like polyhedron, and every edge shared by two faces.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : h.triangles)
    for (int e = 0; e < 3; ++e) ++edges[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}];
  for (const auto& [edge, count] : edges) EXPECT_EQ(count, 2);
  EXPECT_EQ(int(h.vertices.size()) - int(edges.size()) + int(h.triangles.size()), 2);
  // Convex: every input point on or inside every face.
  for (size_t k = 0; k < h.normals.size(); ++k)
    for (const Vec3& q : pts) EXPECT_LE(h.normals[k].dot(q) - h.offsets[k], 1e-12);
  // Every point of the cylinder's rim lies on the hull's surface.
  Vec3 sp, nrm;
  for (size_t k = 0; k < pts.size(); k += 97) EXPECT_NEAR(convex_hull_distance(h, pts[k], sp, nrm), 0.0, 1e-12);
}

TEST(ConvexHull, FlatPointsAreRejected) {
  std::vector<Vec3> pts = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0.5, 0.2, 0)};
  ConvexHull hull;
  std::string error;
  EXPECT_FALSE(convex_hull(pts, hull, error));
  EXPECT_NE(error.find("one plane"), std::string::npos) << error;
}

ToolShape box_shape(const Vec3& h, double rounding = 0) {
  ToolShape t;
  t.kind = ToolShape::Kind::box;
  t.half_size = h;
  t.rounding = rounding;
  return t;
}

TEST(ToolDistance, BoxAndItsConvexHullAgree) {
  const Vec3 h(0.01, 0.02, 0.03);
  auto hull = std::make_shared<ConvexHull>();
  std::string error;
  ASSERT_TRUE(convex_hull(box_corners(h), *hull, error)) << error;
  ToolShape box = box_shape(h), poly;
  poly.kind = ToolShape::Kind::convex;
  poly.hull = hull;
  // Placed the same way anywhere in the world.
  const Eigen::Isometry3d pose = Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized());
  box.pose = poly.pose = pose;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (int k = 0; k < 500; ++k) {
    const Vec3 x = pose * Vec3(u(rng), u(rng), u(rng));
    Vec3 pb, nb, pc, nc;
    const double db = tool_distance(box, x, pb, nb), dc = tool_distance(poly, x, pc, nc);
    ASSERT_NEAR(db, dc, 1e-12) << k;
    EXPECT_LT((pb - pc).norm(), 1e-9) << k;
    // The surface point is on the surface, the normal a unit vector.
    Vec3 p2, n2;
    EXPECT_NEAR(tool_distance(box, pb, p2, n2), 0.0, 1e-12);
    EXPECT_NEAR(nb.norm(), 1.0, 1e-12);
  }
}

TEST(ToolDistance, CapsuleMatchesCapsuleDistance) {
  Capsule c;
  c.p0 = Vec3(0.01, 0.02, 0.0);
  c.p1 = Vec3(-0.05, 0.1, 0.2);
  c.radius = 0.006;
  const ToolShape t = to_tool(c);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.1, 0.2);
  for (int k = 0; k < 500; ++k) {
    const Vec3 x(u(rng), u(rng), u(rng));
    Vec3 p1, n1, p2, n2;
    ASSERT_NEAR(capsule_distance(c, x, p1, n1), tool_distance(t, x, p2, n2), 1e-14);
    EXPECT_LT((p1 - p2).norm(), 1e-14);
  }
  EXPECT_DOUBLE_EQ(t.size(), 0.006);
}

TEST(ToolDistance, CylinderWithRoundedTip) {
  // Radius 5 mm, 40 mm long, edges rounded by 2 mm; axis along z, tip face at z = +20 mm.
  ToolShape t;
  t.kind = ToolShape::Kind::cylinder;
  t.half_size = Vec3(0.005, 0.005, 0.02);
  t.rounding = 0.002;
  Vec3 p, n;
  EXPECT_NEAR(tool_distance(t, Vec3(0, 0, 0.025), p, n), 0.005, 1e-15);  // above the flat tip
  EXPECT_LT((n - Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_NEAR(tool_distance(t, Vec3(0.008, 0, 0), p, n), 0.003, 1e-15);  // beside the side
  EXPECT_NEAR(tool_distance(t, Vec3(0.004, 0, 0), p, n), -0.001, 1e-15);  // inside, nearer the side
  EXPECT_NEAR(tool_distance(t, Vec3(0, 0, 0.017), p, n), -0.003, 1e-15);  // inside, under the tip face
  // Diagonally off the rounded edge: the distance to the fillet's circle minus its radius.
  const Vec3 edge_centre(0.003, 0, 0.018), x = edge_centre + 0.004 * Vec3(1, 0, 1).normalized();
  EXPECT_NEAR(tool_distance(t, x, p, n), 0.002, 1e-15);
  EXPECT_LT((n - Vec3(1, 0, 1).normalized()).norm(), 1e-12);
  // A sharp cylinder's corner is a corner.
  t.rounding = 0;
  EXPECT_NEAR(tool_distance(t, Vec3(0.008, 0, 0.024), p, n), 0.005, 1e-15);
  EXPECT_DOUBLE_EQ(t.size(), 0.005);
}

TEST(ToolDistance, RoundedBoxIsTheCoreSweptByASphere) {
  const ToolShape t = box_shape(Vec3(0.01, 0.01, 0.01), 0.003);
  Vec3 p, n;
  EXPECT_NEAR(tool_distance(t, Vec3(0.02, 0, 0), p, n), 0.01, 1e-15);
  EXPECT_NEAR(tool_distance(t, Vec3(0, 0, 0), p, n), -0.01, 1e-15);
  // Off a corner: distance to the core's corner (7 mm) minus the rounding.
  EXPECT_NEAR(tool_distance(t, Vec3(0.017, 0.017, 0.017), p, n), std::sqrt(3.0) * 0.01 - 0.003, 1e-15);
}

TEST(PushOut, AnyShapeBackAlongTheRelativeMotion) {
  // A box coming down (-z) onto a node: the node ends on the box's bottom face, below where
  // it was, not on a side face.
  ToolShape t = box_shape(Vec3(0.01, 0.01, 0.005));
  t.previous = Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.002));
  const Vec3 x(0.008, 0.0, -0.004);
  Vec3 dir;
  const Vec3 y = push_out(t, x, -t.motion_at(x), dir);
  EXPECT_NEAR(y.z(), -0.005, 1e-12);
  EXPECT_NEAR(y.x(), 0.008, 1e-12);
  EXPECT_LT((dir - Vec3(0, 0, -1)).norm(), 1e-12);
}

}  // namespace
}  // namespace vdm
