#include <gtest/gtest.h>

#include <filesystem>

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
