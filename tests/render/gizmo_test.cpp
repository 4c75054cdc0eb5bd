// The orientation gizmo: the world axes as the camera sees them, farthest drawn first.
#include <gtest/gtest.h>

#include "render/gizmo.hpp"

namespace render {
namespace {

const GizmoAxis& find(const std::array<GizmoAxis, 3>& axes, int a) {
  for (const GizmoAxis& g : axes)
    if (g.axis == a) return g;
  return axes[0];
}

TEST(Gizmo, SeenFromTheFrontAboveZIsUpXRightAndYAway) {
  // The automatic framing's view: from -y, to the right and above.
  const Camera c = auto_frame(Eigen::Vector3d(-0.1, -0.1, -0.1), Eigen::Vector3d(0.1, 0.1, 0.1), 40, 1.5);
  const auto axes = gizmo_axes(c);
  const GizmoAxis &x = find(axes, 0), &y = find(axes, 1), &z = find(axes, 2);
  EXPECT_GT(x.dx, 0.8);          // to the right
  EXPECT_LT(z.dy, -0.5);         // up in the picture (y down)
  EXPECT_NEAR(z.dx, 0, 1e-12);   // z up stays vertical
  EXPECT_GT(y.away, 0);          // y points into the picture...
  EXPECT_LT(z.away, 0);          // ... z toward the camera (seen from above)
  EXPECT_EQ(axes[0].axis, 1);    // the farthest first: drawn under the others
  EXPECT_EQ(axes[2].axis, 2);
  for (const GizmoAxis& g : axes)  // projections of unit vectors
    EXPECT_NEAR(g.dx * g.dx + g.dy * g.dy + g.away * g.away, 1.0, 1e-12);
}

TEST(Gizmo, LookingStraightDownXIsRightAndYIsUp) {
  Camera c;
  c.eye = Eigen::Vector3d(0, 0, 1);
  c.target = Eigen::Vector3d::Zero();
  c.up = Eigen::Vector3d::UnitZ();  // along the view: the camera takes y as up
  const auto axes = gizmo_axes(c);
  EXPECT_NEAR(find(axes, 0).dx, 1, 1e-12);
  EXPECT_NEAR(find(axes, 1).dy, -1, 1e-12);
  EXPECT_NEAR(find(axes, 2).away, -1, 1e-12);  // toward the camera: a dot, drawn last
  EXPECT_EQ(axes[2].axis, 2);
}

}  // namespace
}  // namespace render
