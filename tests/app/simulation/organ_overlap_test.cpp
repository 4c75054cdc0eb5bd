// Two organs passing into each other: spheres a distance d apart (radius r) overlap by 2r - d,
// and the walk from the crossing triangles finds the deepest node inside the other exactly as
// testing every node would.
#include <gtest/gtest.h>

#include <algorithm>

#include "app/simulation/organ_overlap.hpp"
#include "app/simulation/tool_depth.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

constexpr double kRadius = 0.05;

vdm::SurfaceMesh ball_at(double x) {
  vdm::SurfaceMesh m = vdm::make_icosphere(kRadius, 4);
  m.positions.col(0).array() += x;
  return m;
}

// The deepest node of a inside b and of b inside a, testing every node.
double deepest_by_every_node(const vdm::SurfaceMesh& a, const vdm::SurfaceMesh& b) {
  double deepest = 0;
  for (Eigen::Index i = 0; i < a.positions.rows(); ++i)
    deepest = std::max(deepest, depth_inside(b.positions, b.triangles, a.positions.row(i).transpose()));
  for (Eigen::Index i = 0; i < b.positions.rows(); ++i)
    deepest = std::max(deepest, depth_inside(a.positions, a.triangles, b.positions.row(i).transpose()));
  return deepest;
}

TEST(OrganOverlap, SpheresOverlapByTwiceTheRadiusLessTheirDistance) {
  const vdm::SurfaceMesh a = ball_at(0);
  for (double d : {0.08, 0.095, 0.0995}) {
    SCOPED_TRACE(d);
    const vdm::SurfaceMesh b = ball_at(d);
    const OrganOverlap o = find_overlap(a.positions, a.triangles, b.positions, b.triangles);
    EXPECT_TRUE(o.crossing);
    EXPECT_EQ(o.depth, deepest_by_every_node(a, b));
    // The deepest node is on the line between the centres to within the mesh's resolution (a
    // level-4 icosphere's nodes are about 4 degrees apart: 0.2 mm at r = 5 cm).
    EXPECT_NEAR(o.depth, 2 * kRadius - d, 0.0006);
    const vdm::SurfaceMesh& in = o.in_b ? a : b;
    EXPECT_EQ((in.positions.row(o.node).transpose() - o.where).norm(), 0.0);
  }
}

TEST(OrganOverlap, SpheresApartDoNotOverlap) {
  const vdm::SurfaceMesh a = ball_at(0), b = ball_at(0.101), far = ball_at(1.0);
  for (const vdm::SurfaceMesh* other : {&b, &far}) {
    const OrganOverlap o = find_overlap(a.positions, a.triangles, other->positions, other->triangles);
    EXPECT_FALSE(o.crossing);
    EXPECT_EQ(o.depth, 0.0);
  }
}

}  // namespace
}  // namespace vdmsim
