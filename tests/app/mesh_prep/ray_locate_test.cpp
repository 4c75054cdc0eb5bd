// vdmsim locate: the first surface point along a ray and its outward normal.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/mesh_prep/ray_locate.hpp"
#include "app/scene/mesh_io.hpp"
#include "engine/shapes.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

TEST(RayLocate, FirstHitOnASphereIsOnItWithTheOutwardNormal) {
  const vdm::SurfaceMesh s = vdm::make_icosphere(0.05, 4, vdm::Vec3(0.1, 0, 0));
  for (const vdm::Vec3& dir : {vdm::Vec3(0, 0, -1), vdm::Vec3(-1, 0.2, -0.3), vdm::Vec3(0, -2, 0)}) {
    const vdm::Vec3 from = vdm::Vec3(0.1, 0, 0) - 0.3 * dir.normalized();
    const RayHit h = first_hit(s, from, dir);
    ASSERT_TRUE(h.hit);
    const vdm::Vec3 radial = h.point - vdm::Vec3(0.1, 0, 0);
    EXPECT_NEAR(radial.norm(), 0.05, 0.05 * 0.005);          // on the facet: within its sag
    EXPECT_NEAR(h.distance, 0.25, 0.05 * 0.005);             // the near side, not the far one
    EXPECT_GT(h.normal.dot(radial.normalized()), 0.995);     // outward
    EXPECT_NEAR(h.normal.norm(), 1.0, 1e-12);
  }
}

TEST(RayLocate, AMissAndARayFromInside) {
  const vdm::SurfaceMesh s = vdm::make_icosphere(0.05, 3);
  EXPECT_FALSE(first_hit(s, vdm::Vec3(0, 0, 0.2), vdm::Vec3(0, 0, 1)).hit);   // pointing away
  EXPECT_FALSE(first_hit(s, vdm::Vec3(0.2, 0, 0.2), vdm::Vec3(0, 0, -1)).hit);  // passing beside
  EXPECT_FALSE(first_hit(s, vdm::Vec3(0, 0, 0.2), vdm::Vec3::Zero()).hit);
  const RayHit inside = first_hit(s, vdm::Vec3::Zero(), vdm::Vec3(0, 0, 1));
  ASSERT_TRUE(inside.hit);
  EXPECT_GT(inside.normal.z(), 0.99);  // leaving: the normal along the ray
}

TEST(RayLocate, CommandPrintsPointAndNormalInMetresAndExits2OnAMiss) {
  const std::filesystem::path p = test::scratch_dir("ray_locate") / "ball_mm.obj";
  std::string error;
  ASSERT_TRUE(save_obj(vdm::make_icosphere(50, 4), p.string(), "", error)) << error;  // millimetres
  test::CliResult r = test::run_cli(VDMSIM_BINARY, "locate " + p.string() + " --scale 0.001 --from 0 0 0.3 --toward 0 0 -1");
  ASSERT_EQ(r.code, 0) << r.output;
  double x, y, z, nx, ny, nz;
  ASSERT_EQ(std::sscanf(r.output.c_str(), "point: %lf %lf %lf\nnormal: %lf %lf %lf", &x, &y, &z, &nx, &ny, &nz), 6)
      << r.output;
  EXPECT_NEAR(z, 0.05, 0.05 * 0.005);
  EXPECT_NEAR(std::hypot(x, y), 0, 1e-9);
  EXPECT_GT(nz, 0.99);
  r = test::run_cli(VDMSIM_BINARY, "locate " + p.string() + " --scale 0.001 --from 0 0 0.3 --toward 0 0 1");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(p.string() + ": the ray from (0, 0, 0.3) toward (0, 0, 1) misses the surface"), std::string::npos)
      << r.output;
  r = test::run_cli(VDMSIM_BINARY, "locate " + p.string() + " --from 0 0 0.3 --toward 0 0 0");
  EXPECT_EQ(r.code, 2) << r.output;
  r = test::run_cli(VDMSIM_BINARY, "locate /nonexistent/organ.obj --from 0 0 0.3 --toward 0 0 -1");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/organ.obj: no such file"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace vdmsim
