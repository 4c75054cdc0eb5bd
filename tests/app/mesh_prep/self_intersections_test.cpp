// The self-intersection test on organ surfaces: none on the generated livers, the crossing
// triangles named on a surface pushed through itself, the loader refusing it, and its cost
// at 40k nodes.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/mesh_prep/self_intersections.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "engine/stopwatch.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

// The generated liver with its highest node pushed straight down through the underside.
vdm::SurfaceMesh pushed_through_liver() {
  vdm::SurfaceMesh m = make_liver_mesh(4);
  Eigen::Index top = 0;
  m.positions.col(2).maxCoeff(&top);
  m.positions(top, 2) = m.positions.col(2).minCoeff() - 0.01;
  return m;
}

TEST(SelfIntersections, NoneOnTheGeneratedLiver) {
  const SelfIntersections s = find_self_intersections(make_liver_mesh(4), 10);
  EXPECT_TRUE(s.tested);
  EXPECT_FALSE(s.any);
  EXPECT_TRUE(s.pairs.empty());
}

TEST(SelfIntersections, APushedThroughNodeCrossesAndIsNamed) {
  const vdm::SurfaceMesh m = pushed_through_liver();
  const SelfIntersections one = find_self_intersections(m);
  EXPECT_TRUE(one.any);
  EXPECT_EQ(one.pairs.size(), 1u);  // 0: stop at the first
  const SelfIntersections s = find_self_intersections(m, 100);
  ASSERT_TRUE(s.any);
  EXPECT_GE(s.pairs.size(), 6u);  // the node's fan (6 triangles) through the underside
  for (const auto& [a, b] : s.pairs) {
    EXPECT_LT(a, b);
    EXPECT_LT(b, m.triangle_count());
  }
  EXPECT_NE(s.text(2).find("triangles " + std::to_string(s.pairs[0][0]) + " and "), std::string::npos);
  EXPECT_NE(s.text(2).find(", ..."), std::string::npos);
}

TEST(SelfIntersections, NotTestedOnANonManifoldSurface) {
  vdm::SurfaceMesh m = make_liver_mesh(3);
  m.triangles.conservativeResize(m.triangles.rows() + 1, 3);
  m.triangles.row(m.triangles.rows() - 1) = m.triangles.row(0);  // an edge shared by three triangles
  EXPECT_FALSE(find_self_intersections(m).tested);
}

TEST(SelfIntersections, TheLoaderRefusesASelfIntersectingOrgan) {
  const std::filesystem::path p = test::scratch_dir("self_intersections") / "pushed.obj";
  std::string error;
  ASSERT_TRUE(save_obj(pushed_through_liver(), p.string(), "", error)) << error;
  const MeshLoadResult r = load_surface_mesh(p.string());
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.problem, vdm::MeshProblem::self_intersection);
  EXPECT_NE(r.error.find(p.string() + ": self-intersection: the surface passes through itself (triangles "),
            std::string::npos)
      << r.error;
  EXPECT_NE(r.error.find("prepare-mesh"), std::string::npos) << r.error;
}

// The loader runs the test on every organ: at 40962 nodes it must stay a small part of a load.
TEST(SelfIntersections, A40kNodeLiverHasNone) {
  const vdm::SurfaceMesh m = make_liver_mesh(6);
  ASSERT_EQ(m.node_count(), 40962);
  const auto t0 = vdm::Clock::now();
  const SelfIntersections s = find_self_intersections(m);
  const double ms = vdm::ms_since(t0);
  EXPECT_FALSE(s.any);
  std::printf("self-intersection test on %d nodes: %.0f ms\n", m.node_count(), ms);
}

}  // namespace
}  // namespace vdmsim
