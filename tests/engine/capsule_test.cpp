// The capsule term (docs/model.md, "the capsule"): the membrane converges under mesh
// refinement, the paper's edge weights do not; both keep the volume exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/contact.hpp"
#include "engine/geometry.hpp"
#include "engine/mesh_topology.hpp"
#include "render/render_scene.hpp"
#include "support/flat_punch.hpp"
#include "support/irregular_liver.hpp"

namespace vdm {
namespace {

using punch::PunchCase;
using punch::PunchResult;
using punch::run_punch;

void print(const char* what, int cells, const PunchResult& r) {
  std::printf("%s %3d cells (%6d nodes): dent 10 mm %.4f mm, 20 mm %.4f mm; force %.4f N; volume error %.1e\n", what,
              cells, r.nodes, 1e3 * r.dent[0], 1e3 * r.dent[1], r.force, r.volume_error);
}

double relative_change(double coarse, double fine) { return std::abs(fine - coarse) / std::abs(fine); }

TEST(MembraneCapsule, FlatPunchConvergesUnderRefinement) {
  // A square punch of half-width 5 mm, its edges on mesh lines at every resolution: a round
  // punch's footprint on this lattice (the nodes within its radius) changes with the mesh by
  // a share of a cell, an O(h) error of the loading itself that hides the model's.
  PunchCase c;
  c.square = true;
  const std::vector<double> at = {0.010, 0.020};
  const PunchResult r20 = run_punch(c, 20, at), r40 = run_punch(c, 40, at), r80 = run_punch(c, 80, at);
  print("membrane", 20, r20);
  print("membrane", 40, r40);
  print("membrane", 80, r80);
  for (const PunchResult* r : {&r20, &r40, &r80}) EXPECT_LT(std::abs(r->volume_error), 1e-9);
  // The criterion: under 10 % between the two finest meshes, for both dents and the force.
  EXPECT_LT(relative_change(r40.dent[0], r80.dent[0]), 0.10);
  EXPECT_LT(relative_change(r40.dent[1], r80.dent[1]), 0.10);
  EXPECT_LT(relative_change(r40.force, r80.force), 0.10);
  // A dimple, not a pinhole: the surface 2 punch radii out goes down by a share of the depth.
  EXPECT_LT(r80.dent[0], -0.1 * c.depth);
}

TEST(PaperCapsule, FlatPunchDentFadesUnderRefinement) {
  // The paper's literal weights scale with the cell area: the dent beside the punch shrinks
  // towards the nodes under it as the mesh is refined (the defect the membrane form mends).
  PunchCase c;
  c.capsule = CapsuleForm::paper;
  const std::vector<double> at = {0.010, 0.020};
  const PunchResult r20 = run_punch(c, 20, at), r40 = run_punch(c, 40, at);
  print("paper   ", 20, r20);
  print("paper   ", 40, r40);
  EXPECT_LT(std::abs(r40.dent[0]), 0.5 * std::abs(r20.dent[0]));
}

}  // namespace
}  // namespace vdm

// --- The stress view on an irregular surface ---------------------------------------------

namespace vdm {
namespace {

// The share of the top 1 % of the default stress view's quantity (stress magnitude) that lies
// within `radius` of `point`.
double top_share_near(const TissueModel& m, const SimState& s, const Vec3& point, double radius) {
  std::vector<float> q;
  render::scalar_field(render::Quantity::stress_magnitude, s, q);
  std::vector<int> order;
  for (int i = 0; i < m.n; ++i) order.push_back(i);
  const size_t top = std::max<size_t>(1, order.size() / 100);
  std::partial_sort(order.begin(), order.begin() + long(top), order.end(),
                    [&](int a, int b) { return q[size_t(a)] > q[size_t(b)]; });
  size_t near = 0;
  for (size_t k = 0; k < top; ++k) near += (s.x.row(order[k]).transpose() - point).norm() <= radius;
  return double(near) / double(top);
}

TEST(MembraneCapsule, StressViewFindsTheProbeOnAnIrregularSurface) {
  // A 4 mm probe pressed 10 mm into the right lobe of a jittered, edge-flipped liver (10k
  // nodes), underside fixed: the top 1 % of the stress magnitude lies within 3 cm of it. (With
  // the membrane's force per node instead of its strain, half of the top 1 % was along the
  // fixed underside's rim, where the pressure's bulge meets the support.)
  const SurfaceMesh mesh = test::irregular_liver(5, 11);
  MeshCheck check;
  SurfaceMesh checked = mesh;
  check = check_and_orient_surface(checked);
  ASSERT_TRUE(check.ok()) << check.message;
  const Vec3 touch(0.035, 0.0, 0.0603), up(0, 0, 1);
  const double r = 0.004, depth = 0.010;
  for (const CapsuleForm form : {CapsuleForm::membrane, CapsuleForm::paper}) {
    TissueDef def = default_tissue(checked);
    def.capsule = form;
    def.fixed = FlagMat::Zero(def.mesh.node_count(), 3);
    for (int i = 0; i < def.mesh.node_count(); ++i)
      if (def.mesh.positions(i, 2) < -0.03) def.fixed.row(i).setOnes();
    TissueModel m;
    std::string error;
    ASSERT_TRUE(build_tissue_model(def, m, error)) << error;
    SimState s = make_sim_state(m);
    ContactSolver contact(m);
    const StepInput base = make_step_input(m);
    ContactReport rep;
    const int steps = 20;
    for (int k = 0; k <= steps; ++k) {
      const Vec3 tip = touch + (0.002 - (depth + 0.002) * k / steps) * up;
      contact.step(m, base, {capsule_shape(tip + r * up, tip + 0.2 * up, r, k ? Vec3(-(depth + 0.002) / steps * up) : Vec3::Zero())},
                   s, rep);
      ASSERT_FALSE(s.failed) << s.failure;
    }
    const double share = top_share_near(m, s, touch, 0.03);
    std::printf("%s capsule: contact force %.3f N, %d nodes; top 1 %% of the stress magnitude within 3 cm: %.0f %%\n",
                to_string(form), rep.force.norm(), rep.nodes, 100 * share);
    EXPECT_GT(rep.nodes, 0);
    if (form == CapsuleForm::membrane) {
      EXPECT_EQ(share, 1.0);
    }
  }
}

}  // namespace
}  // namespace vdm
