// The elastic core (engine/core): its lattice fills the organ, a rigid motion costs nothing,
// the volume is kept, and a pulled bar takes the elastic answer.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "engine/core/elastic_core.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/surface_force_law.hpp"
#include "support/cantilever.hpp"
#include "support/free_input.hpp"
#include "support/held_below.hpp"

namespace vdm::core {
namespace {

using test::held_below;

constexpr double kYoung = 3000;

CoreModel build(const SurfaceMesh& s, double h, const FlagMat& fixed = FlagMat()) {
  CoreDef def;
  def.surface = s;
  def.young_modulus = kYoung;
  def.cell_size = h;
  def.fixed = fixed;
  CoreModel m;
  std::string error;
  EXPECT_TRUE(build_core_model(def, m, error)) << error;
  return m;
}

TEST(ElasticCore, LatticeFillsTheOrgan) {
  // The cubes' inside parts add up to the organ's volume (64 samples per cube), on a sphere
  // and on a box the lattice does not fit.
  for (const double h : {0.01, 0.005}) {
    const SurfaceMesh sphere = make_icosphere(0.05, 4);
    const CoreModel m = build(sphere, h);
    const double filled = m.fill.sum() * h * h * h;
    EXPECT_NEAR(filled / m.rest_volume, 1.0, 0.03) << "sphere, h " << h;
    const SurfaceMesh box = make_box(Vec3(0.1, 0.04, 0.03), 10, 4, 3);
    const CoreModel b = build(box, h);
    EXPECT_NEAR(b.fill.sum() * h * h * h / b.rest_volume, 1.0, 0.03) << "box, h " << h;
    // Every surface node is tied with weights that reproduce its rest position.
    for (int i = 0; i < b.ns; ++i) {
      Vec3 p = Vec3::Zero();
      double sum = 0;
      for (int k = 0; k < 4; ++k) {
        p += b.tie_weight(i, k) * b.lattice.row(b.tie_node(i, k)).transpose();
        sum += b.tie_weight(i, k);
        EXPECT_GE(b.tie_weight(i, k), -1e-12);
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
      EXPECT_LT((p - box.positions.row(i).transpose()).norm(), 1e-12);
    }
  }
}

TEST(ElasticCore, UnitCubeEdgesGiveTheDeformationGradient) {
  // The rotation fit reads F - I along each tet's edges (the motion's differences); that is the
  // gradients' sum, sum_a v_a (x) grad N_a, for any corner motion.
  const UnitCube& cube = unit_cube();
  Eigen::Matrix<double, 8, 3> v;
  for (int k = 0; k < 8; ++k) v.row(k) = Vec3(std::sin(1.0 + k), std::cos(2.0 * k), 0.1 * k * k - 0.3);
  for (int t = 0; t < 6; ++t) {
    Eigen::Matrix3d by_gradients = Eigen::Matrix3d::Zero(), by_edges = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 4; ++a) by_gradients += v.row(cube.corner[t][a]).transpose() * cube.grad[t].row(a);
    for (int k = 0; k < 3; ++k)
      by_edges.col(cube.edge_axis[t][k]) = (v.row(cube.corner[t][k + 1]) - v.row(cube.corner[t][k])).transpose();
    EXPECT_LT((by_gradients - by_edges).cwiseAbs().maxCoeff(), 1e-14) << "tet " << t;
  }
}

TEST(ElasticCore, RigidMotionCostsNothing) {
  // Every surface node prescribed to a large rigid rotation and translation: the lattice
  // follows, and no node needs a force.
  // (The iteration's tolerance tightened from its default so that the lattice's answer is
  // exact to far below the 1e-8 m checked.)
  const SurfaceMesh s = make_box(Vec3(0.06, 0.03, 0.02), 6, 3, 2);
  CoreModel m = build(s, 0.007);
  m.settings.tolerance = 1e-9;
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.8, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(0.01, -0.02, 0.005);
  for (int i = 0; i < m.ns; ++i) {
    const Vec3 X = s.positions.row(i);
    in.prescribed.row(i).setOnes();
    in.prescribed_u.row(i) = (R * X + t - X).transpose();
  }
  step(m, in, st);
  EXPECT_TRUE(st.stats.converged);
  const double scale = kYoung * 0.06 * 0.06;  // a force of the organ's size for a strain of 1
  EXPECT_LT(st.reaction.cwiseAbs().maxCoeff(), 1e-7 * scale);
  for (int k = 0; k < m.ng; ++k) {
    const Vec3 Y = m.lattice.row(k);
    EXPECT_LT((st.v.row(k).transpose() - (R * Y + t - Y)).norm(), 1e-8);
  }
}

TEST(ElasticCore, PressKeepsTheVolumeAndBulgesTheRest) {
  // A ball, its bottom held, a top cap pressed 5 mm: the volume is kept to 1e-9 and the free
  // surface bulges out; the press costs a force that grows with the depth.
  const SurfaceMesh s = make_icosphere(0.04, 4);
  const FlagMat fixed = held_below(s, -0.035);
  const CoreModel m = build(s, 0.008, fixed);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  double last_force = 0;
  for (int k = 1; k <= 2; ++k) {
    for (int i = 0; i < m.ns; ++i)
      if (s.positions(i, 2) > 0.036) {
        in.prescribed.row(i).setOnes();
        in.prescribed_u(i, 2) = -0.0025 * k;
      }
    step(m, in, st);
    ASSERT_TRUE(st.stats.converged);
    EXPECT_LT(std::abs(st.volume_rel_error), 1e-9);
    // The constraints push the cap down (reaction < 0); the organ pushes the press up.
    double force = 0;
    for (int i = 0; i < m.ns; ++i)
      if (s.positions(i, 2) > 0.036) force -= st.reaction(i, 2);
    EXPECT_GT(force, 1.5 * last_force);
    last_force = force;
  }
  // The equator moves outwards.
  double radial = 0;
  int count = 0;
  for (int i = 0; i < m.ns; ++i)
    if (std::abs(s.positions(i, 2)) < 0.004) {
      const Vec3 X = s.positions.row(i);
      radial += st.u.row(i).dot(Vec3(X.x(), X.y(), 0).normalized());
      ++count;
    }
  EXPECT_GT(radial / count, 1e-4);
}

TEST(ElasticCore, HeldBaseCarriesTheWeight) {
  // A ball on its held base under gravity: the base's reactions carry the lattice's weight
  // (the pressure's forces cancel over the closed surface), which is the organ's within the
  // inside samples' accuracy; the top sags.
  const SurfaceMesh s = make_icosphere(0.04, 4);
  CoreDef def;
  def.surface = s;
  def.young_modulus = kYoung;
  def.cell_size = 0.008;
  def.use_gravity = true;
  def.fixed = held_below(s, -0.03);
  CoreModel m;
  std::string error;
  ASSERT_TRUE(build_core_model(def, m, error)) << error;
  CoreState st = make_core_state(m);
  step(m, test::free_input(m.ns), st);
  ASSERT_TRUE(st.stats.converged);
  const double weight = def.density * m.rest_volume * 9.81;
  EXPECT_NEAR(st.reaction.col(2).sum() / weight, 1.0, 0.03);
  EXPECT_LT(std::abs(st.reaction.col(0).sum()), 1e-6 * weight);
  EXPECT_LT(std::abs(st.volume_rel_error), 1e-9);
  int top = 0;
  for (int i = 1; i < m.ns; ++i)
    if (s.positions(i, 2) > s.positions(top, 2)) top = i;
  EXPECT_LT(st.u(top, 2), 0);
}

// A law that sets no forces of its own but, like friction, is no potential's: the iteration's
// mixes are then judged by the safeguard (the merit of the energy each iteration minimises).
class NonConservativeLaw final : public SurfaceForceLaw {
 public:
  bool update(const NodeMat&, ComplianceSource&, NodeMat&) override { return false; }
};

TEST(ElasticCore, JointIterationJudgesItsMixesOnTheForcesAsTheyStand) {
  // The iteration in its parts, as organs stepped together drive it: after each solve and its
  // convergence test the caller changes the surface forces (another organ's push on the cap,
  // easing off toward its limit as a contact's does), moves the answer by them and takes the
  // residual again. The next mix is judged against the merit with the forces as they now
  // stand, which the plain step from the last iterate lowers: 8 iterations, no mix refused.
  // (Judged against the merit with the forces before the change, the easing push made nearly
  // every mix look uphill: 15 iterations, 13 mixes refused.)
  const SurfaceMesh s = make_icosphere(0.04, 4);
  const CoreModel m = build(s, 0.008, held_below(s, -0.035));
  CoreState st = make_core_state(m);
  NonConservativeLaw law;
  std::vector<int> cap;
  for (int i = 0; i < m.ns; ++i)
    if (s.positions(i, 2) > 0.034) cap.push_back(i);
  ASSERT_GT(cap.size(), 3u);
  StepInput in = test::free_input(m.ns);
  in.force = NodeMat::Zero(m.ns, 3);
  for (int i : cap) in.force(i, 2) = -0.1 / static_cast<double>(cap.size());
  ASSERT_TRUE(begin_step(m, in, st, &law));
  int iterations = 0;
  for (;;) {
    solve_iteration(m, st);
    ++iterations;
    const bool fixed = iteration_converged(m, st);
    const double push = 0.05 * (1 + std::pow(0.5, iterations)) / static_cast<double>(cap.size());  // N a node
    for (int i : cap) iteration_forces(st)(i, 2) = -push;
    forces_changed(m, st);
    mixing_residual(m, st);
    if (!advance_iteration(m, st, fixed)) break;
  }
  end_step(m, st);
  ASSERT_TRUE(st.stats.converged);
  EXPECT_LT(std::abs(st.volume_rel_error), 1e-9);
  EXPECT_LT(st.u(cap.front(), 2), 0.0);
  EXPECT_LE(st.stats.anderson_rejected, iterations / 4) << iterations << " iterations";
  std::cout << iterations << " iterations, " << st.stats.anderson_rejected << " mixes refused\n";
}

TEST(ElasticCore, HeldEntriesGiveTheFactorisedAnswerWithoutRefactorising) {
  // A ball on its held base, a cap pressed deeper and wider at every step (as a contact's held
  // set grows). Held by multipliers through the first factor (the default), each step gives
  // what a lattice factorised with every prescribed entry gives, and nothing is factorised
  // again. The factorised reference factorises at every step (its prescribed set grows),
  // with more ties than the first factor's symbolic analysis saw.
  // The base is held on every axis, a ring above it on z only: x and y share a factor, z has
  // its own.
  const SurfaceMesh s = make_icosphere(0.04, 4);
  FlagMat fixed = held_below(s, -0.035);
  for (int i = 0; i < fixed.rows(); ++i)
    if (s.positions(i, 2) < -0.03) fixed(i, 2) = 1;
  CoreModel held = build(s, 0.008, fixed);
  held.settings.tolerance = 1e-7;  // both converged far below the differences checked
  CoreModel factorised = held;
  factorised.settings.max_held = 0;
  CoreState a = make_core_state(held), b = make_core_state(factorised);
  StepInput in = test::free_input(held.ns);
  int refactorisations = 0;
  for (int k = 1; k <= 3; ++k) {
    int pressed = 0;
    for (int i = 0; i < held.ns; ++i)
      if (s.positions(i, 2) > 0.039 - 0.0005 * k) {
        in.prescribed.row(i).setOnes();
        in.prescribed_u.row(i) = Vec3(0.0002 * k, 0, -0.002 * k).transpose();  // down, and a little sideways
        ++pressed;
      }
    ASSERT_LE(3 * pressed, held.settings.max_held);
    step(held, in, a);
    step(factorised, in, b);
    ASSERT_TRUE(a.stats.converged && b.stats.converged);
    EXPECT_EQ(a.stats.factorizations, k == 1 ? 2 : 0);
    if (k > 1) refactorisations += a.stats.factorizations;
    EXPECT_EQ(b.stats.factorizations, 2);  // x and y share one
    const double scale = b.u.cwiseAbs().maxCoeff();
    EXPECT_LT((a.u - b.u).cwiseAbs().maxCoeff(), 1e-4 * scale) << "step " << k;
    EXPECT_LT((a.v - b.v).cwiseAbs().maxCoeff(), 1e-4 * scale) << "step " << k;
    const double force = b.reaction.cwiseAbs().maxCoeff();
    EXPECT_LT((a.reaction - b.reaction).cwiseAbs().maxCoeff(), 1e-3 * force) << "step " << k;
    EXPECT_NEAR(a.pressure, b.pressure, 1e-3 * std::abs(b.pressure)) << "step " << k;
    EXPECT_LT(std::abs(a.volume_rel_error), 1e-9);
  }
  EXPECT_EQ(refactorisations, 0);
}

TEST(ElasticCore, SurfaceComplianceIsSymmetricAndHoldsWhatIsHeld) {
  // The compliance at a few top nodes after a press: symmetric, positive on the diagonal,
  // zero on the held entries, and softer at a free node than what holds a neighbour allows.
  const SurfaceMesh s = make_icosphere(0.04, 4);
  const FlagMat fixed = held_below(s, -0.035);
  const CoreModel m = build(s, 0.008, fixed);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  std::vector<int> top;
  for (int i = 0; i < m.ns; ++i)
    if (s.positions(i, 2) > 0.037) top.push_back(i);
  ASSERT_GE(top.size(), 3u);
  step(m, in, st);
  Eigen::MatrixXd free_C, held_C;
  surface_compliance(m, st, top, free_C);
  in.prescribed.row(top[0]).setOnes();  // hold the first node where it is
  step(m, in, st);
  surface_compliance(m, st, top, held_C);
  const int n = static_cast<int>(top.size());
  EXPECT_LT((free_C - free_C.transpose()).cwiseAbs().maxCoeff(), 1e-9 * free_C.cwiseAbs().maxCoeff());
  EXPECT_LT((held_C - held_C.transpose()).cwiseAbs().maxCoeff(), 1e-9 * held_C.cwiseAbs().maxCoeff());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(free_C).eigenvalues().minCoeff(), 0.0);
  EXPECT_EQ(held_C.topRows(3).cwiseAbs().maxCoeff(), 0.0);
  for (int a = 1; a < n; ++a)
    for (int d = 0; d < 3; ++d) {
      EXPECT_GT(free_C(3 * a + d, 3 * a + d), 0.0);
      EXPECT_LE(held_C(3 * a + d, 3 * a + d), free_C(3 * a + d, 3 * a + d) * (1 + 1e-9));
    }
}

// A law that presses `nodes` down with `force` in all (N), spread evenly, and, like a contact
// point whose force changes from one linearisation to the next, adds a chatter that alternates
// in sign and eases off by `ease` an update, starting at `chatter` (N; 0: a steady push).
class PressingLaw final : public SurfaceForceLaw {
 public:
  PressingLaw(std::vector<int> nodes, double force, double chatter = 0, double ease = 1)
      : nodes_(std::move(nodes)), force_(force), chatter_(chatter), ease_(ease) {}
  bool update(const NodeMat&, ComplianceSource&, NodeMat& force) override {
    const double per_node = (force_ + (updates_ % 2 ? chatter_ : -chatter_)) / static_cast<double>(nodes_.size());
    bool changed = false;
    for (int i : nodes_) {
      changed = changed || force(i, 2) != -per_node;
      force(i, 2) = -per_node;
    }
    chatter_ *= ease_;
    ++updates_;
    return changed;
  }

 private:
  std::vector<int> nodes_;
  double force_, chatter_, ease_;
  int updates_ = 0;
};

TEST(ElasticCore, ALawsChatterAtItsOwnNodesDoesNotHoldTheIterationBack) {
  // A ball held at its base, pressed on its cap by a law whose force chatters (1 % of the push,
  // alternating in sign and easing off by 3 % an update, as a contact point's force changes
  // while its points join, leave and slip). The imbalance the chatter leaves is at the lattice
  // nodes that tie the law's nodes, and the law's own test judges it. The step stops once the
  // positions are within the tolerance (9 iterations, the steady press 8), within the
  // tolerance of the same press without the chatter; counted in the force balance, the
  // chatter held the step until it fell below a thousandth of the elastic forces (56).
  const SurfaceMesh s = make_icosphere(0.04, 4);
  const CoreModel m = build(s, 0.008, held_below(s, -0.035));
  std::vector<int> cap;
  for (int i = 0; i < m.ns; ++i)
    if (s.positions(i, 2) > 0.034) cap.push_back(i);
  ASSERT_GT(cap.size(), 3u);
  const double push = 0.03;  // N
  auto press = [&](double chatter, int& iterations) {
    CoreState st = make_core_state(m);
    PressingLaw law(cap, push, chatter, 0.97);
    step(m, test::free_input(m.ns), st, &law);
    EXPECT_TRUE(st.stats.converged);
    EXPECT_LT(std::abs(st.volume_rel_error), 1e-9);
    iterations = st.stats.iterations;
    return st.u;
  };
  int steady_iterations = 0, chattering_iterations = 0;
  const NodeMat steady = press(0.0, steady_iterations);
  const NodeMat chattering = press(0.01 * push, chattering_iterations);
  const double tolerance_m = m.settings.tolerance * m.size;
  EXPECT_LT(steady.col(2).minCoeff(), -20 * tolerance_m);  // a dent, many tolerances deep
  EXPECT_LT((chattering - steady).cwiseAbs().maxCoeff(), tolerance_m);
  EXPECT_LE(chattering_iterations, 20) << "steady press: " << steady_iterations << " iterations";
}

// The 10 cm cantilever of the bending tests (1 cm square, held at its root).
constexpr double kBeamLength = 0.1;
SurfaceMesh bending_beam() { return test::cantilever_surface(kBeamLength, 0.01, 40, 4); }

// Its tip's sag (m), solved in one static step (E 5 MPa, 2.5 mm cells) at these tolerances,
// under its weight (no law) or under `law`'s forces.
double beam_sag(const SurfaceMesh& beam, double tolerance, double force_tolerance, SurfaceForceLaw* law) {
  CoreDef def;
  def.surface = beam;
  def.young_modulus = 5e6;
  def.cell_size = 0.0025;
  def.fixed = test::cantilever_root(beam);
  def.use_gravity = law == nullptr;
  def.settings.tolerance = tolerance;
  def.settings.force_tolerance = force_tolerance;
  def.settings.max_iterations = 2000;
  CoreModel m;
  std::string error;
  EXPECT_TRUE(build_core_model(def, m, error)) << error;
  CoreState s = make_core_state(m);
  step(m, test::free_input(m.ns), s, law);
  EXPECT_TRUE(s.stats.converged);
  return -test::cantilever_tip_z(beam, s.u, kBeamLength);
}

// At the default tolerances the sag is within five tolerances (of the beam's size) of the same
// step solved a thousand times tighter.
void expect_sag_near_fixed_point(const SurfaceMesh& beam, SurfaceForceLaw* law) {
  const CoreSettings defaults;
  const double loose = beam_sag(beam, defaults.tolerance, defaults.force_tolerance, law);
  const double tight = beam_sag(beam, 1e-3 * defaults.tolerance, 1e-3 * defaults.force_tolerance, law);
  ASSERT_GT(tight, 1e-3);
  const double tolerance_m = defaults.tolerance * std::sqrt(kBeamLength * kBeamLength + 2 * 0.01 * 0.01);
  EXPECT_LT(std::abs(loose - tight), 5 * tolerance_m) << "sag " << loose << " m, converged " << tight << " m";
}

TEST(ElasticCore, LoadedBendingStopsNearItsFixedPoint) {
  // A cantilever bent by its weight: the rotations' fixed point converges slowly (the change
  // per iteration is small long before the answer is near). At the default tolerances the
  // tip's sag is within a few tolerances of the same step solved a thousand times tighter:
  // the iteration stagnates (its rate creeps to 0.997, 0.01 tolerance a step, where the
  // estimate of the distance left swings from 0.1 to 5 tolerances), and where it stops
  // between about 2 and 3 tolerances short (0.9-1.2 % of the sag) is a matter of round-off.
  // Five tolerances still tell a worse stop: one that trusts the forces' balance less
  // (relative to the displacement) ends 10 tolerances short (4 %).
  expect_sag_near_fixed_point(bending_beam(), nullptr);
}

TEST(ElasticCore, BendingByALawsLoadStopsNearItsFixedPoint) {
  // The cantilever of LoadedBendingStopsNearItsFixedPoint bent by a load on its tip that a law
  // sets: the force balance is not counted at the lattice nodes that tie the law's nodes, but
  // the rotations' slow mode spreads its imbalance along the beam, where it still holds the
  // iteration until the tip is within a few tolerances of the same step solved a thousand
  // times tighter. (With no force balance at all the step stops where it starts: 0.01 mm of
  // the 2.5 mm sag.)
  const SurfaceMesh beam = bending_beam();
  std::vector<int> tip;
  for (Eigen::Index i = 0; i < beam.positions.rows(); ++i)
    if (beam.positions(i, 0) > kBeamLength - 1e-9) tip.push_back(static_cast<int>(i));
  ASSERT_GT(tip.size(), 3u);
  PressingLaw law(tip, 0.04);
  expect_sag_near_fixed_point(beam, &law);
}

}  // namespace

}  // namespace vdm::core
