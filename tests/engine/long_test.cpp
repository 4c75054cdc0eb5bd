// Long hard cases (issue 7), CTest label `long`: the 40k-node liver and 100 000 steps of
// cyclic loading.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/scene/mesh_io.hpp"
#include "support/hard_cases.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

TEST(Long, FortyThousandNodeLiverPressed) {
  const auto path = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L6.obj";
  const vdmsim::MeshLoadResult mesh = vdmsim::load_surface_mesh(path.string());
  ASSERT_TRUE(mesh.ok) << mesh.error;
  TissueDef def = default_tissue(mesh.mesh);
  const int n = def.mesh.node_count();
  ASSERT_GT(n, 40000);
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.03) def.fixed.row(i).setOnes();
  const TissueModel m = scenario::build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  const Vec3 c(0.035, -0.01, 0.06);
  for (int k = 1; k <= 10; ++k) {
    for (int i = 0; i < n; ++i)
      if ((m.rest.positions.row(i).transpose() - c).norm() < 0.015) {
        in.prescribed(i, 2) = 1;
        in.prescribed_u(i, 2) = -0.0015 * k;
      }
    step(m, in, s);
    hard::expect_sensible(m, s, 0.03, "40k step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    EXPECT_EQ(s.stats.fallbacks, 0);
  }
}

TEST(Long, HundredThousandCyclicStepsDoNotDrift) {
  // A small ball pressed on its top by up to 1 cm and released, 1000 cycles of 100 steps.
  const double R = 0.05;
  const TissueModel m = scenario::build(default_tissue(make_icosphere(R, 1)));
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  const int top = nearest_node(m.rest.positions, Vec3(0, 0, R));
  const int steps = 100000, period = 100;
  double worst_volume = 0;
  for (int k = 1; k <= steps; ++k) {
    const double load = 0.5 * (1.0 - std::cos(2.0 * M_PI * k / period));  // 0 at each cycle's end
    in.prescribed(top, 2) = 1;
    in.prescribed_u(top, 2) = -0.01 * load;
    step(m, in, s);
    worst_volume = std::max(worst_volume, std::abs(s.volume_rel_error));
    if (k % 10000 == 0) {
      hard::expect_sensible(m, s, 0.02, "cyclic step " + std::to_string(k));
      ASSERT_FALSE(HasFailure());
    }
  }
  // Unloaded: a few steps at zero load settle the last step's geometric lag.
  for (int k = 0; k < 5; ++k) step(m, in, s);
  EXPECT_LT(worst_volume, 1e-6);
  EXPECT_LT(std::abs(s.volume_rel_error), 1e-6);
  EXPECT_LT(s.u.cwiseAbs().maxCoeff(), 1e-6 * m.size) << "rest shape recovered";
}

}  // namespace
}  // namespace vdm
