#include <gtest/gtest.h>

#include <filesystem>

#include "app/mesh_prep/self_intersections.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "engine/geometry.hpp"
#include "engine/mesh_topology.hpp"
#include "engine/sim_state.hpp"

namespace vdmsim {
namespace {

TEST(OrganGenerator, LiverIsAValidOutwardSurfaceOfLiverSize) {
  vdm::SurfaceMesh m = make_liver_mesh(4);
  EXPECT_EQ(m.node_count(), 2562);
  const vdm::MeshCheck c = vdm::check_and_orient_surface(m);
  EXPECT_TRUE(c.ok()) << c.message;
  EXPECT_FALSE(c.flipped);
  const double v = vdm::enclosed_volume(m.positions, m.triangles, vdm::Vec3::Zero());
  EXPECT_GT(v, 1.2e-3);  // an adult liver holds about 1.2 to 2 litres
  EXPECT_LT(v, 2.5e-3);
  // Every node lies on the implicit surface.
  const LiverShape shape;
  for (int i = 0; i < m.node_count(); ++i) EXPECT_NEAR(shape.value(m.positions.row(i).transpose()), 0.0, 1e-9);
}

TEST(OrganGenerator, GallbladderIsAValidOutwardSacOfAnAdultsSize) {
  vdm::SurfaceMesh m = make_gallbladder_mesh(4);
  EXPECT_EQ(m.node_count(), 2562);
  const vdm::MeshCheck c = vdm::check_and_orient_surface(m);
  EXPECT_TRUE(c.ok()) << c.message;
  EXPECT_FALSE(c.flipped);
  const SelfIntersections crossing = find_self_intersections(m);
  EXPECT_TRUE(crossing.tested);
  EXPECT_FALSE(crossing.any) << crossing.text();
  // An adult's gallbladder: 7 to 10 cm long, 3 to 4 cm across its body, 30 to 50 ml.
  const double v = vdm::enclosed_volume(m.positions, m.triangles, vdm::Vec3::Zero());
  EXPECT_GT(v, 30e-6);
  EXPECT_LT(v, 50e-6);
  const vdm::Vec3 size = m.positions.colwise().maxCoeff() - m.positions.colwise().minCoeff();
  EXPECT_GT(size.x(), 0.07);
  EXPECT_LT(size.x(), 0.10);
  EXPECT_GT(size.y(), 0.028);
  EXPECT_LT(size.y(), 0.04);
  // Pear-shaped: the fundus's half (x < 0) wider than the neck's end (the last 2 cm).
  const double x_hi = m.positions.col(0).maxCoeff();
  double fundus_width = 0, neck_width = 0;
  for (int i = 0; i < m.node_count(); ++i) {
    const double x = m.positions(i, 0), y = std::abs(m.positions(i, 1));
    if (x < 0) fundus_width = std::max(fundus_width, y);
    if (x > x_hi - 0.02) neck_width = std::max(neck_width, y);
  }
  EXPECT_GT(fundus_width, 2 * neck_width);
  // The mesh reaches both ends of the shape (its nodes on the surface alone would not show a
  // neck cut short by too few nodes there): within 0.5 mm of the farthest inside points along x.
  const GallbladderShape shape;
  double inside_lo = 0, inside_hi = 0;
  for (double z = -0.01; z <= 0.015; z += 5e-4)
    for (double x = -0.06; x <= 0.08; x += 1e-4)
      if (shape.value(vdm::Vec3(x, 0, z)) < 0) inside_lo = std::min(inside_lo, x), inside_hi = std::max(inside_hi, x);
  EXPECT_GT(x_hi, inside_hi - 5e-4);
  EXPECT_LT(m.positions.col(0).minCoeff(), inside_lo + 5e-4);
  // Every node on the implicit surface; no sliver (the worst triangle's 2 r_in / r_out).
  double worst = 1;
  for (int i = 0; i < m.node_count(); ++i) EXPECT_NEAR(shape.value(m.positions.row(i).transpose()), 0.0, 1e-9);
  for (int k = 0; k < m.triangle_count(); ++k) {
    const vdm::Vec3 a = m.positions.row(m.triangles(k, 0)), b = m.positions.row(m.triangles(k, 1)),
                    cc = m.positions.row(m.triangles(k, 2));
    const double la = (b - cc).norm(), lb = (cc - a).norm(), lc = (a - b).norm(), sp = 0.5 * (la + lb + lc);
    const double area = (b - a).cross(cc - a).norm() / 2;
    worst = std::min(worst, 8 * area * area / (sp * la * lb * lc));
  }
  EXPECT_GT(worst, 0.3);
}

TEST(OrganGenerator, CommittedMeshesMatchTheGenerator) {
  const std::filesystem::path dir = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes";
  for (int level : {4, 5}) {
    const auto path = dir / ("liver_L" + std::to_string(level) + ".obj");
    const MeshLoadResult r = load_surface_mesh(path.string());
    ASSERT_TRUE(r.ok) << r.error;
    const vdm::SurfaceMesh g = make_liver_mesh(level);
    ASSERT_EQ(r.mesh.node_count(), g.node_count());
    ASSERT_EQ(r.mesh.triangles, g.triangles) << "regenerate with: vdmsim make-organ liver --level " << level;
    EXPECT_LT((r.mesh.positions - g.positions).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(OrganGenerator, PokedLiverKeepsItsVolumeAndBulges) {
  vdm::TissueDef def = vdm::default_tissue(make_liver_mesh(4));
  const int n = def.mesh.node_count();
  def.fixed = vdm::FlagMat::Zero(n, 3);
  const double zmin = def.mesh.positions.col(2).minCoeff();
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < zmin + 0.01) def.fixed.row(i).setOnes();  // resting on its underside
  vdm::TissueModel m;
  std::string err;
  ASSERT_TRUE(vdm::build_tissue_model(def, m, err)) << err;
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::StepInput in = vdm::make_step_input(m);
  // Push the nodes within 1.5 cm of the top of the right lobe down by up to 15 mm.
  int top = 0;
  for (int i = 0; i < n; ++i)
    if (m.rest.positions(i, 2) > m.rest.positions(top, 2)) top = i;
  for (int k = 1; k <= 15; ++k) {
    for (int i = 0; i < n; ++i)
      if ((m.rest.positions.row(i) - m.rest.positions.row(top)).norm() < 0.015) {
        in.prescribed(i, 2) = 1;
        in.prescribed_u(i, 2) = -0.001 * k;
      }
    vdm::step(m, in, s);
    ASSERT_LT(std::abs(s.volume_rel_error), 1e-9) << "step " << k;
  }
  // Somewhere away from the push, the surface moved outward.
  double bulge = 0.0;
  for (int i = 0; i < n; ++i) {
    if ((m.rest.positions.row(i) - m.rest.positions.row(top)).norm() < 0.05) continue;
    bulge = std::max(bulge, s.u.row(i).dot(s.area_vectors.row(i).normalized()));
  }
  EXPECT_GT(bulge, 1e-4);
  EXPECT_GT(s.pressure, 0.0);
}

}  // namespace
}  // namespace vdmsim
