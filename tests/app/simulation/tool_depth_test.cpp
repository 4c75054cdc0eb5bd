#include "app/simulation/tool_depth.hpp"

#include <gtest/gtest.h>

#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

TEST(ToolDepth, DeeperInsideAgreesWithTheDepthWithAndWithoutANodeNearby) {
  // A 5 cm sphere: points from its centre (about 5 cm from every node, so the nodes cannot
  // settle it) to outside, against limits below and above their depths.
  const double R = 0.05;
  const vdm::SurfaceMesh s = vdm::make_icosphere(R, 3);
  int through_triangles = 0;
  for (const double r : {0.0, 0.01, 0.03, 0.045, 0.049, 0.06}) {
    const vdm::Vec3 p(r * 0.6, -r * 0.8, 0.0);
    const double depth = depth_inside(s.positions, s.triangles, p);
    if (r < 0.045) {
      EXPECT_GT(depth, 0.0) << r;
    }
    if (r > R) {
      EXPECT_EQ(depth, 0.0) << r;
    }
    for (const double limit : {0.001, 0.01, 0.02, 0.04, 0.045, 0.1}) {
      EXPECT_EQ(deeper_inside(s.positions, s.triangles, p, limit), depth > limit) << r << " " << limit;
      through_triangles += depth > limit;
    }
  }
  EXPECT_GT(through_triangles, 3);  // cases where no node was within the limit and the tip was deep
}

}  // namespace
}  // namespace vdmsim
