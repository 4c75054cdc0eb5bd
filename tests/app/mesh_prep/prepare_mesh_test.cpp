// vdmsim prepare-mesh on livers the project damages itself (app/scene/scan_like_organ): the
// result is a valid organ (closed, outward, one piece, no self-intersection), and it meets the
// issue's targets: smallest angle >= 20 deg, volume within 2 %, mean distance <= 1.5 mm.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "app/mesh_prep/mesh_quality.hpp"
#include "app/mesh_prep/prepare_mesh.hpp"
#include "app/mesh_prep/self_intersections.hpp"
#include "app/mesh_prep/surface_distance.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/scene/scan_like_organ.hpp"
#include "engine/shapes.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {
namespace fs = std::filesystem;

fs::path dir() { return test::scratch_dir("prepare_mesh"); }

std::string write(const vdm::SurfaceMesh& m, const std::string& name) {
  const fs::path p = dir() / name;
  std::string error;
  EXPECT_TRUE(save_obj(m, p.string(), "", error)) << error;
  return p.string();
}

struct Prepared {
  int code = -1;
  std::string out, err;
  MeshLoadResult mesh;  // the output, loaded as a scene would (validated, self-intersection tested)
};

Prepared prepare(PrepareMeshOptions opt) {
  Prepared r;
  std::ostringstream out, err;
  r.code = cmd_prepare_mesh(opt, out, err);
  r.out = out.str();
  r.err = err.str();
  if (r.code == 0) r.mesh = load_surface_mesh(opt.out);
  return r;
}

TEST(PrepareMesh, EdgeLengthForNodesOnASphere) {
  const vdm::SurfaceMesh s = vdm::make_icosphere(0.05, 4);  // 2562 nearly equilateral triangles' nodes
  const MeshQuality q = measure_mesh(s);
  EXPECT_NEAR(edge_length_for_nodes(q.area, s.node_count()), q.mean_edge, 0.05 * q.mean_edge);
}

// Jitter only (no crop, no fold): the result keeps the volume and lies as close to the
// undamaged liver as the bumpy input did, its worst bump flattened.
TEST(PrepareMesh, BumpyLiverComesBackCloseToTheUndamagedOne) {
  ScanLikeOptions damage;
  damage.level = 4;
  damage.crop_mm = 0;
  damage.fold = false;
  damage.jitter_mm = 1.0;
  damage.scanner_offset_mm = vdm::Vec3::Zero();
  PrepareMeshOptions opt;
  const vdm::SurfaceMesh bumpy = make_scan_like_liver(damage);
  opt.in = write(bumpy, "bumpy.obj");
  opt.out = (dir() / "bumpy_prepared.obj").string();
  opt.scale = 0.001;
  opt.nodes = 3000;
  const Prepared r = prepare(opt);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  ASSERT_TRUE(r.mesh.ok) << r.mesh.error;
  const vdm::SurfaceMesh truth = make_liver_mesh(5);
  const MeshQuality q = measure_mesh(r.mesh.mesh), t = measure_mesh(truth);
  EXPECT_NEAR(q.nodes, 3000, 90) << r.out;
  EXPECT_GE(q.smallest_angle_deg, 20.0) << r.out;
  EXPECT_NEAR(q.volume, t.volume, 0.02 * t.volume) << r.out;
  const SurfaceDistance d = sampled_distance(r.mesh.mesh, truth, 50000);
  vdm::SurfaceMesh bumpy_m = bumpy;
  bumpy_m.positions *= 0.001;
  const SurfaceDistance d0 = sampled_distance(bumpy_m, truth, 50000);
  std::printf("bumpy liver (jitter 1 mm): %d nodes, smallest angle %.1f deg, volume %+.2f %%; distance to the "
              "undamaged liver: prepared mean %.3f mm max %.3f mm, input mean %.3f mm max %.3f mm\n",
              q.nodes, q.smallest_angle_deg, 100 * (q.volume - t.volume) / t.volume, d.mean * 1e3, d.max * 1e3,
              d0.mean * 1e3, d0.max * 1e3);
  // Measured: prepared mean 0.41 mm, max 4.0 mm; the bumpy input 0.40 mm, 5.0 mm. The mean stays
  // at the bumps' own level (far under the 1.5 mm target), the worst bump is flattened.
  EXPECT_LT(d.mean, d0.mean + 0.1e-3);
  EXPECT_LT(d.max, d0.max);
  EXPECT_NE(r.out.find("targets: smallest angle >= 20 deg met, volume within 2 % met, mean distance <= 1.5 mm met"),
            std::string::npos)
      << r.out;
}

// Everything at once: millimetres, scanner coordinates, jitter, an open crop, small holes,
// duplicate triangles and a fold pushed through the underside.
TEST(PrepareMesh, ScanLikeLiverBecomesAValidOrgan) {
  ScanLikeOptions damage;
  damage.level = 4;
  const vdm::SurfaceMesh scan = make_scan_like_liver(damage);
  PrepareMeshOptions opt;
  opt.in = write(scan, "scan.obj");
  ASSERT_FALSE(load_surface_mesh(opt.in, {}).ok);  // no organ as it is
  opt.out = (dir() / "scan_prepared.obj").string();
  opt.scale = 0.001;
  opt.nodes = 3000;
  opt.center = true;
  const Prepared r = prepare(opt);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  ASSERT_TRUE(r.mesh.ok) << r.mesh.error;  // closed, outward, one piece, no crossing
  EXPECT_FALSE(r.mesh.flipped);
  const MeshQuality q = measure_mesh(r.mesh.mesh);
  EXPECT_NEAR(q.nodes, 3000, 90) << r.out;
  EXPECT_GE(q.smallest_angle_deg, 20.0) << r.out;
  EXPECT_LT((0.5 * (q.lo + q.hi)).norm(), 1e-9);  // --center
  const double extent = (q.hi - q.lo).maxCoeff();
  EXPECT_GT(extent, 0.2);  // metres: the liver, not 1000 times it
  EXPECT_LT(extent, 0.35);
  // The report names what was repaired.
  EXPECT_NE(r.out.find("holes filled"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("crossing triangle pairs removed"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("crossing triangle pairs (some remain)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[0."), std::string::npos) << r.out;  // progress lines with their time
  EXPECT_NE(r.out.find("mean distance <= 1.5 mm met"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("smallest angle >= 20 deg met"), std::string::npos) << r.out;
}

TEST(PrepareMesh, BadInputExits2NamingTheProblem) {
  PrepareMeshOptions opt;
  opt.in = "/nonexistent/scan.obj";
  opt.out = (dir() / "never.obj").string();
  Prepared r = prepare(opt);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/scan.obj: no such file"), std::string::npos) << r.err;

  opt.in = write(vdm::make_icosphere(0.05, 2), "ball.obj");
  opt.nodes = 500;
  opt.edge_length = 0.01;
  r = prepare(opt);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not both"), std::string::npos) << r.err;

  opt.nodes = 0;
  opt.edge_length = 0.5;  // longer than the ball
  r = prepare(opt);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("too long"), std::string::npos) << r.err;

  // A lone triangle: nothing to close into an organ.
  vdm::SurfaceMesh tri;
  tri.positions.resize(3, 3);
  tri.positions << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0;
  tri.triangles.resize(1, 3);
  tri.triangles << 0, 1, 2;
  opt.in = write(tri, "triangle.obj");
  opt.edge_length = 0;
  r = prepare(opt);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(opt.in + ": "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(opt.out));
}

}  // namespace
}  // namespace vdmsim
