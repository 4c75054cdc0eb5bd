#include <gtest/gtest.h>

#include "engine/geometry.hpp"
#include "engine/shapes.hpp"

namespace vdm {
namespace {

TEST(Geometry, BoxVolumeAndAreaAreExact) {
  const SurfaceMesh box = make_box(Vec3(0.2, 0.3, 0.5), 3, 4, 5);
  EXPECT_NEAR(enclosed_volume(box.positions, box.triangles, Vec3(1, 2, 3)), 0.03, 1e-15);
  EXPECT_NEAR(surface_area(box.positions, box.triangles), 2 * (0.06 + 0.1 + 0.15), 1e-14);
}

}  // namespace
}  // namespace vdm
