#include <gtest/gtest.h>

#include "engine/mesh_topology.hpp"
#include "engine/shapes.hpp"

namespace vdm {
namespace {

TEST(Shapes, GeneratedSurfacesAreValidOrgans) {
  for (SurfaceMesh m : {make_box(Vec3(1, 2, 3), 2, 3, 4), make_icosphere(1, 3), make_uv_sphere(1, 8, 12)}) {
    const MeshCheck c = check_and_orient_surface(m);
    EXPECT_TRUE(c.ok()) << c.message;
    EXPECT_FALSE(c.flipped);
  }
}

TEST(Shapes, BoxNodeCount) {
  // Lattice nodes on the surface plus one centre node per quad.
  const int nx = 3, ny = 4, nz = 5;
  const int lattice = (nx + 1) * (ny + 1) * (nz + 1) - (nx - 1) * (ny - 1) * (nz - 1);
  const int quads = 2 * (nx * ny + ny * nz + nx * nz);
  const SurfaceMesh m = make_box(Vec3(1, 1, 1), nx, ny, nz);
  EXPECT_EQ(m.node_count(), lattice + quads);
  EXPECT_EQ(m.triangle_count(), 4 * quads);
}

TEST(Shapes, IcosphereCounts) {
  const SurfaceMesh m = make_icosphere(1.0, 3);
  EXPECT_EQ(m.node_count(), 10 * 64 + 2);
  EXPECT_EQ(m.triangle_count(), 20 * 64);
  EXPECT_NEAR(m.positions.rowwise().norm().minCoeff(), 1.0, 1e-14);
}

}  // namespace
}  // namespace vdm
