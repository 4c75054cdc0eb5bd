// Hard cases on the elastic core (issue 42): a deep press (with friction and without), a
// squeeze and a free ball pushed, with constraint contact (by default friction 0.2, solved
// inside the core's iteration), and the awkward meshes (slivers of aspect 1e4, cells differing
// 100 times) compressed by 30 %. Each step ends finite, with the volume to round-off, no
// collapsed triangle, no folded edge (to each case's measured limit; support/hard_cases.hpp),
// converged (the frictionless press: all but at most one step), and no free node in a probe.
// Label `long`.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "app/scene/mesh_io.hpp"
#include "engine/contact.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/organ_solver.hpp"
#include "engine/tool_shape.hpp"
#include "support/hard_cases.hpp"
#include "support/held_below.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

using hard::expect_sensible;
using test::held_below;

// The organ's surface model with `fixed` held, and its core (E 5 kPa, cells of `h`).
struct Organ {
  TissueModel m;
  std::unique_ptr<OrganSolver> core;
};

Organ organ(const SurfaceMesh& mesh, const FlagMat& fixed, double h) {
  Organ o;
  TissueDef def = default_tissue(mesh);
  def.fixed = fixed;
  std::string error;
  EXPECT_TRUE(build_tissue_model(def, o.m, error)) << error;
  core::CoreDef cd;
  cd.surface = o.m.rest;
  cd.young_modulus = 5000;
  cd.cell_size = h;
  cd.fixed = o.m.held;
  core::CoreModel cm;
  EXPECT_TRUE(core::build_core_model(cd, cm, error)) << error;
  o.core = make_core_solver(std::move(cm), 0.05);
  return o;
}

// A probe of radius r, tip at `tip`, pointing along `axis` (handle to tip), moved by `motion`
// over the step.
ToolShape probe(const Vec3& tip, const Vec3& axis, double r, const Vec3& motion) {
  return capsule_shape(tip - r * axis, tip - (r + 0.2) * axis, r, motion);
}

// The deepest node that no contact point holds inside any tool (m).
double free_penetration(const SimState& s, const ContactSolver& cs, const std::vector<ToolShape>& tools) {
  double worst = 0;
  for (int i = 0; i < s.x.rows(); ++i) {
    if (cs.active()[static_cast<size_t>(i)]) continue;
    for (const ToolShape& t : tools) {
      Vec3 p, n;
      worst = std::max(worst, -tool_distance(t, s.x.row(i).transpose(), p, n));
    }
  }
  return worst;
}

// An 8 mm probe pressed 1 mm a step to half a 10 cm ball's depth, with constraint contact of
// friction `mu`: every step sound (finite, the volume to round-off, nothing inside the probe,
// the force growing with the depth). Returns how many of the 51 steps ended unconverged.
int press_to_half_depth(double mu) {
  const double R = 0.05, r = 0.008, step_m = 1e-3;
  const SurfaceMesh ball = make_icosphere(R, 4);
  Organ o = organ(ball, held_below(ball, -0.045), 0.008);
  SimState s = make_sim_state(o.m);
  const StepInput base = make_step_input(o.m);
  ContactSettings settings;
  settings.friction = mu;
  ContactSolver cs(o.m, settings);
  cs.set_solver(o.core.get());
  ContactReport rep;
  double last_force = 0;
  int unconverged = 0;
  for (int k = 0; k <= 50; ++k) {  // 5 cm: half of the 10 cm depth
    const std::vector<ToolShape> tools = {probe(Vec3(0, 0, R - k * step_m), -Vec3::UnitZ(), r,
                                                k ? Vec3(0, 0, -step_m) : Vec3::Zero())};
    cs.step(o.m, base, tools, s, rep);
    expect_sensible(o.m, s, 0.06, "depth " + std::to_string(k) + " mm");
    if (::testing::Test::HasFailure()) return unconverged;
    unconverged += !rep.converged;
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-12) << "depth " << k;
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "depth " << k;
    // The force grows with the depth but for stick-slip: with friction 0.2 it dipped by 3.5 %
    // where contact points began to slip (frictionless, by 0.4 % where points joined).
    if (k > 0) {
      EXPECT_GE(rep.force.z(), 0.95 * last_force) << "the force fell, depth " << k;
    }
    last_force = rep.force.z();
  }
  EXPECT_GT(last_force, 0.0);
  return unconverged;
}

TEST(CoreHard, ProbePressedToHalfTheBallsDepth) {
  EXPECT_EQ(press_to_half_depth(ContactSettings{}.friction), 0);  // the default friction, 0.2
}

// The same press without friction: every contact point slides along the tip. Its mixing is
// unguarded (the law's forces are a constraint's); at most one step of the 51 ends unconverged
// (its iteration creeps until its residual stalls), every step as sound.
TEST(CoreHard, FrictionlessProbePressedToHalfTheBallsDepth) { EXPECT_LE(press_to_half_depth(0.0), 1); }

// An organ held nowhere, pushed by a probe: with no inertia nothing resists a rigid motion (the
// core's regularisation, 1e-10 of its stiffness, only keeps it solvable), so the ball moves
// ahead of the probe, the force stays a vanishing share of what the same press into a held ball
// takes, every step converges and the volume holds.
TEST(CoreHard, AFreeBallPushedByAProbeMovesAheadOfItWithoutForce) {
  const double R = 0.05, r = 0.008, step_m = 2e-3;
  const SurfaceMesh ball = make_icosphere(R, 3);
  const FlagMat none = FlagMat::Zero(ball.node_count(), 3);
  double force[2] = {0, 0};
  Vec3 centroid_moved = Vec3::Zero();
  for (int held = 0; held < 2; ++held) {
    Organ o = organ(ball, held ? held_below(ball, -0.045) : none, 0.01);
    SimState s = make_sim_state(o.m);
    const StepInput base = make_step_input(o.m);
    ContactSolver cs(o.m);
    cs.set_solver(o.core.get());
    ContactReport rep;
    for (int k = 0; k <= 5; ++k) {  // 10 mm down from touching the top
      const std::vector<ToolShape> tools = {probe(Vec3(0, 0, R - k * step_m), -Vec3::UnitZ(), r,
                                                  k ? Vec3(0, 0, -step_m) : Vec3::Zero())};
      cs.step(o.m, base, tools, s, rep);
      expect_sensible(o.m, s, 0.06, "held " + std::to_string(held) + ", step " + std::to_string(k));
      ASSERT_FALSE(HasFailure());
      EXPECT_TRUE(rep.converged) << "held " << held << ", step " << k;
      EXPECT_LT(std::abs(s.volume_rel_error), 1e-12);
      EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r);
    }
    force[held] = rep.force.z();
    if (!held) centroid_moved = (s.x - o.m.rest.positions).colwise().mean().transpose();
  }
  EXPECT_GT(force[1], 0.0);
  EXPECT_LT(std::abs(force[0]), 1e-4 * force[1]) << "free " << force[0] << " N, held " << force[1] << " N";
  // The free ball went down with the probe (its top stays on the tip; its shape barely changes).
  EXPECT_NEAR(centroid_moved.z(), -5 * step_m, 0.1 * 5 * step_m);
  EXPECT_LT(std::abs(centroid_moved.x()) + std::abs(centroid_moved.y()), 0.1 * 5 * step_m);
}

TEST(CoreHard, LiverSqueezedBetweenTwoProbes) {
  const auto path = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj";
  const vdmsim::MeshLoadResult mesh = vdmsim::load_surface_mesh(path.string());
  ASSERT_TRUE(mesh.ok) << mesh.error;
  // The left lobe's end held (the squeeze is on the right lobe): the organ cannot drift.
  FlagMat fixed = FlagMat::Zero(mesh.mesh.node_count(), 3);
  for (int i = 0; i < mesh.mesh.node_count(); ++i)
    if (mesh.mesh.positions(i, 0) < -0.1) fixed.row(i).setOnes();
  Organ o = organ(mesh.mesh, fixed, 0.01);
  const double x0 = 0.035, y0 = 0.0, r = 0.01;
  double top = -1, bottom = 1;
  for (int i = 0; i < o.m.n; ++i)
    if (std::hypot(o.m.rest.positions(i, 0) - x0, o.m.rest.positions(i, 1) - y0) < 0.01) {
      top = std::max(top, o.m.rest.positions(i, 2));
      bottom = std::min(bottom, o.m.rest.positions(i, 2));
    }
  ASSERT_GT(top - bottom, 0.05);
  SimState s = make_sim_state(o.m);
  const StepInput base = make_step_input(o.m);
  ContactSolver cs(o.m);
  cs.set_solver(o.core.get());
  ContactReport rep;
  const double squeeze = 0.02, start = 0.002;  // each probe travels 2 cm in (4 cm of ~9)
  const int steps = 40;
  for (int k = 0; k <= steps; ++k) {
    const double d = -start + (squeeze + start) * k / steps, v = k ? (squeeze + start) / steps : 0.0;
    const std::vector<ToolShape> tools = {probe(Vec3(x0, y0, top - d), -Vec3::UnitZ(), r, Vec3(0, 0, -v)),
                                          probe(Vec3(x0, y0, bottom + d), Vec3::UnitZ(), r, Vec3(0, 0, v))};
    cs.step(o.m, base, tools, s, rep);
    expect_sensible(o.m, s, 0.05, "squeeze step " + std::to_string(k));
    ASSERT_FALSE(HasFailure());
    EXPECT_TRUE(rep.converged) << "step " << k;
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-12) << "step " << k;
    EXPECT_LE(free_penetration(s, cs, tools), 0.02 * r) << "step " << k;
  }
  EXPECT_GT(rep.nodes, 0);
  EXPECT_GT(s.pressure, 0.0);  // squeezed: the fluid pushes out
}

// A cube of side L on its held base, its top pressed down by `fraction` of L in `steps`
// prescribed steps. Folds are checked up to `fold_free` and convergence up to `converged_to`
// (fractions of L): the measured limits.
// The core has no skin: below a cell each node is tied to the core alone and the fluid's
// pressure moves it along its own area vector, so where neighbouring area vectors differ
// (slivers across the cube's edges, the graded cube's smallest cells) the surface folds at the
// scale of those triangles while the organ's shape stays sound.
void compress(const SurfaceMesh& mesh, double L, double fraction, int steps, const std::string& what,
              double fold_free, double converged_to = 1.0) {
  Organ o = organ(mesh, held_below(mesh, -L / 2 + 1e-12), L / 8);
  SimState s = make_sim_state(o.m);
  StepInput in = make_step_input(o.m);
  for (int k = 1; k <= steps; ++k) {
    scenario::press_top(o.m, L, -fraction * L * k / steps, in);
    o.core->step(in, s);
    expect_sensible(o.m, s, 1.5 * L, what + " step " + std::to_string(k), fraction * k / steps <= fold_free + 1e-12);
    ASSERT_FALSE(::testing::Test::HasFailure());
    if (fraction * k / steps <= converged_to + 1e-12) {
      EXPECT_TRUE(s.stats.converged) << what << " step " << k << ": " << s.stats.iterations << " iterations";
    }
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-12) << what << " step " << k;
  }
}

TEST(CoreHard, SliverTrianglesOfAspect1e4CompressedBy30Percent) {
  // Folds from the first 2 % step (21 edges of the 1e-4-wide column): not checked. From 24 % a
  // step ends unconverged at its 400 iterations, its shape sound to 30 % as the graded cube's.
  compress(hard::sliver_cube(0.1), 0.1, 0.3, 15, "slivers", -1.0, 0.22);
}

TEST(CoreHard, CellsDiffering100TimesCompressedBy30Percent) {
  // One edge folds at 8 %: checked to 6 %. From 14 % the rotations' fixed point creeps (the
  // surface moves 3e-3 of the size an iteration, shrinking by 1 % every 10) and a step ends
  // unconverged at its 400 iterations; the shape stays sound (finite, volume, no collapse,
  // bounded) to 30 %.
  compress(hard::graded_cube(0.1), 0.1, 0.3, 15, "graded", 0.06, 0.12);
}

}  // namespace
}  // namespace vdm
