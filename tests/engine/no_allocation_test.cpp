// Once warmed up, a step allocates nothing: counted by wrapping glibc's malloc family.
// Built as its own executable (the wrapper would fight a sanitizer's allocator).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

#include "engine/contact.hpp"
#include "engine/organ_pair_contact.hpp"
#include "engine/organ_solver.hpp"
#include "engine/shapes.hpp"
#include "support/scenarios.hpp"

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
}

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
void note() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t a, size_t b) {
  note();
  return __libc_calloc(a, b);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
int posix_memalign(void** out, size_t align, size_t n) {
  note();
  *out = __libc_memalign(align, n);
  return *out ? 0 : 12;
}
void* aligned_alloc(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
}

namespace vdm {
namespace {

long allocations_in_steps(SolverMethod method, bool contact_set_changes) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 6, method);
  def.use_gravity = true;
  const TissueModel m = scenario::build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  auto load = [&](int k) {
    in.clear();
    // A pressed patch that grows with k when the contact set changes.
    const double radius = contact_set_changes ? 0.01 + 0.004 * k : 0.03;
    for (int i = 0; i < m.n; ++i) {
      const Vec3 X = m.rest.positions.row(i);
      if (X.z() > L / 2 - 1e-12 && X.head<2>().norm() < radius) {
        in.prescribed(i, 2) = 1;
        in.prescribed_u(i, 2) = -0.001 * k;
      }
    }
  };
  for (int k = 1; k <= 3; ++k) {  // warm-up
    load(k);
    step(m, in, s);
  }
  long total = 0;
  for (int k = 4; k <= 8; ++k) {
    load(k);
    g_allocations = 0;
    g_counting = true;
    step(m, in, s);
    g_counting = false;
    total += g_allocations;
  }
  EXPECT_LT(std::abs(s.volume_rel_error), 1e-9);
  return total;
}

TEST(NoAllocation, CounterSeesAnAllocation) {
  g_allocations = 0;
  g_counting = true;
  std::vector<double>* v = new std::vector<double>(100);
  g_counting = false;
  EXPECT_GE(g_allocations.load(), 2);
  delete v;
}

TEST(NoAllocation, StructuredStepAfterWarmUp) {
  EXPECT_EQ(allocations_in_steps(SolverMethod::structured, false), 0);
  EXPECT_EQ(allocations_in_steps(SolverMethod::structured, true), 0);
}

TEST(NoAllocation, ReferenceStepAfterWarmUp) {
  EXPECT_EQ(allocations_in_steps(SolverMethod::reference, false), 0);
  EXPECT_EQ(allocations_in_steps(SolverMethod::reference, true), 0);
}

TEST(NoAllocation, DirectStepAfterWarmUp) {
  // Refactorisation included: every step here refreshes the matrix.
  EXPECT_EQ(allocations_in_steps(SolverMethod::direct, false), 0);
  EXPECT_EQ(allocations_in_steps(SolverMethod::direct, true), 0);
}

// Steps done in halved load increments (a beam pulled to three times its length in one step,
// then let go, over and over): the fallback allocates nothing either once it has been met.
TEST(NoAllocation, HalvedStepAfterWarmUp) {
  const double length = 0.1;
  const TissueModel m = scenario::build(scenario::clamped_beam(length, 0.02, 10, 2));
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  auto load = [&](int k) { scenario::move_end(m, length, Vec3(0, k % 2 ? 2.0 * length : 0.0, 0), in); };
  for (int k = 1; k <= 4; ++k) {  // warm-up, two halved steps among them
    load(k);
    step(m, in, s);
  }
  long total = 0;
  int halved = 0;
  for (int k = 5; k <= 10; ++k) {
    load(k);
    g_allocations = 0;
    g_counting = true;
    step(m, in, s);
    g_counting = false;
    total += g_allocations;
    ASSERT_FALSE(s.failed) << s.failure;
    halved += s.stats.fallback != nullptr;
  }
  EXPECT_EQ(halved, 3);
  EXPECT_EQ(total, 0);
}

// Contact steps with a tool of each kind pressing the cube's top further each step (the
// active set changes): nothing allocated once warmed up.
// `borrow`: ContactSolver::step with the input itself (not a copy) for its solves.
// `whole_press`: the warm-up is a whole press, a withdrawal and a second press, and the
// withdrawal and press are then repeated and counted (constraint contact keeps arrays sized
// by the number of contact points, which grows as the tool goes deeper: they are warm once
// they have held the largest contact).
long allocations_in_contact_steps(ToolShape::Kind kind, ContactSettings settings = {}, bool borrow = false,
                                  bool whole_press = false) {
  const double L = 0.1;
  const TissueModel m = scenario::build(scenario::cube_on_table(L, 6));
  SimState s = make_sim_state(m);
  StepInput input = make_step_input(m);
  const StepInput& base = input;
  ContactSolver contact(m, settings);
  ContactReport rep;
  ToolShape t;
  t.kind = kind;
  t.half_size = Vec3(0.02, 0.02, 0.02);
  t.rounding = kind == ToolShape::Kind::capsule ? 0.02 : 0.002;
  auto hull = std::make_shared<ConvexHull>();
  if (kind == ToolShape::Kind::convex) {
    std::vector<Vec3> corners;
    for (int k = 0; k < 8; ++k) corners.emplace_back(k & 1 ? 0.02 : -0.02, k & 2 ? 0.02 : -0.015, k & 4 ? 0.02 : -0.02);
    std::string error;
    EXPECT_TRUE(convex_hull(corners, *hull, error)) << error;
    t.hull = hull;
    t.rounding = 0;
  }
  std::vector<ToolShape> tools(1);
  const double reach = kind == ToolShape::Kind::capsule ? 0.04 : 0.02;  // centre to the bottom
  auto press = [&](int k, int from) {
    t.previous = Eigen::Isometry3d(Eigen::Translation3d(0, 0, L / 2 + reach - 0.001 * from));
    t.pose = Eigen::Isometry3d(Eigen::Translation3d(0, 0, L / 2 + reach - 0.001 * k));
    tools[0] = t;
    if (borrow) contact.step(m, input, tools, s, rep);
    else contact.step(m, base, tools, s, rep);
  };
  // The depths of the counted steps (a step from the depth before).
  std::vector<int> counted = {4, 5, 6, 7, 8};
  if (whole_press) {
    // Down, back up and down again (the contacts of a press after a withdrawal differ from
    // the first's): once as the warm-up, then counted.
    counted = {7, 6, 5, 4, 3, 2, 1, 2, 3, 4, 5, 6, 7, 8};
    for (int k = 1; k <= 8; ++k) press(k, k - 1);
    int last = 8;
    for (int k : counted) {
      press(k, last);
      last = k;
    }
  } else {
    for (int k = 1; k <= 3; ++k) press(k, k - 1);  // warm-up
  }
  long total = 0;
  int from = whole_press ? 8 : 3;
  for (int k : counted) {
    g_allocations = 0;
    g_counting = true;
    press(k, from);
    g_counting = false;
    from = k;
    total += g_allocations;
    EXPECT_GT(rep.nodes, 0);
  }
  EXPECT_LT(std::abs(s.volume_rel_error), 1e-6);
  return total;
}

TEST(NoAllocation, KinematicContactStepAfterWarmUp) {
  ContactSettings sticking;
  sticking.method = ContactSettings::Method::kinematic;
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::capsule, sticking), 0);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::cylinder, sticking), 0);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::box, sticking), 0);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::convex, sticking), 0);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::capsule, sticking, true), 0);
  ContactSettings refit_every_query = sticking;
  refit_every_query.lazy_refit = false;
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::box, refit_every_query), 0);
}

TEST(NoAllocation, ConstraintContactStepAfterWarmUp) {
  ContactSettings frictional;  // the default method
  frictional.friction = 0.3;
  ContactSettings lazy_off = frictional;
  lazy_off.lazy_refit = false;
  for (ToolShape::Kind kind :
       {ToolShape::Kind::capsule, ToolShape::Kind::cylinder, ToolShape::Kind::box, ToolShape::Kind::convex})
    EXPECT_EQ(allocations_in_contact_steps(kind, frictional, false, true), 0) << static_cast<int>(kind);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::box, lazy_off, false, true), 0);
}

TEST(NoAllocation, PenaltyContactStepAfterWarmUp) {
  ContactSettings penalty;
  penalty.method = ContactSettings::Method::penalty;
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::capsule, penalty), 0);
  EXPECT_EQ(allocations_in_contact_steps(ToolShape::Kind::box, penalty), 0);
}

// An organ whose every node moves alone, by `c` metres per newton: the compliance the
// contact between organs asks for, without a model behind it.
class UniformCompliance final : public OrganSolver {
 public:
  explicit UniformCompliance(double c) : c_(c) {}
  ModelKind kind() const override { return ModelKind::vdm_core; }
  void step(const StepInput&, SimState&) override {}
  void trial_step(const StepInput&, SimState&, StepResults) override {}
  void finish_step(SimState&) override {}
  void rewind(SimState&) override {}
  const NodeMat& start_u(const SimState& s) const override { return s.u; }
  bool takes_springs() const override { return false; }
  bool takes_tolerance() const override { return false; }
  const AxisStiffness& contact_stiffness(const TissueModel&, const SimState&) override { return stiffness_; }
  long contact_stiffness_version(const SimState&) const override { return 0; }
  // (The matrix is resized when the nodes' count changes: those allocations are the model's,
  // counted apart in `own`.)
  bool surface_compliance(const std::vector<int>& nodes, Eigen::MatrixXd& C) override {
    const Eigen::Index n = 3 * static_cast<Eigen::Index>(nodes.size());
    const long before = g_allocations;
    C.setIdentity(n, n);
    own += g_allocations - before;
    C *= c_;
    return true;
  }
  long own = 0;

 private:
  double c_;
  AxisStiffness stiffness_;
};

// Contact and ties between two organs, one pressed further into the other each step and
// drawn back (the points change): nothing allocated once the deepest press has been seen.
TEST(NoAllocation, ContactBetweenOrgansAfterWarmUp) {
  const SurfaceMesh a = make_icosphere(0.03, 2), b = make_icosphere(0.03, 2);
  std::vector<OrganTie> ties;
  for (int k = 0; k < 4; ++k) {  // a's nodes nearest b, tied to b's triangle 0
    OrganTie t;
    t.owner = 0;
    t.other = 1;
    t.node = k;
    for (int v = 0; v < 3; ++v) t.corner[v] = b.triangles(0, v);
    t.stiffness = 50;
    ties.push_back(t);
  }
  OrganPairContact pair({static_cast<int>(a.positions.rows()), static_cast<int>(b.positions.rows())}, {0.01, 0.0101},
                        0.3, ties);
  UniformCompliance ca(1e-3), cb(2e-3);
  const std::vector<OrganSolver*> solvers = {&ca, &cb};
  NodeMat xa = a.positions, xb = b.positions, fa = NodeMat::Zero(xa.rows(), 3), fb = NodeMat::Zero(xb.rows(), 3);
  const std::vector<const TriMat*> triangles = {&a.triangles, &b.triangles};
  std::vector<const NodeMat*> x = {&xa, &xb};
  auto step = [&](int depth) {  // b's centre 6 cm - depth mm from a's
    xb = b.positions.rowwise() + Vec3(0.06 - 0.001 * depth, 0, 0).transpose();
    x[1] = &xb;
    pair.begin_step(x);
    for (int round = 0; round < 3; ++round) {
      pair.find_points(x, triangles, 0.002);
      double violation = 0, change = 0;
      EXPECT_TRUE(pair.correct(solvers, violation, change));
      pair.apply(0, fa);
      x[1] = &pair.predict(1, xb);
    }
    pair.apply(1, fb);
    pair.end_step();
  };
  const std::vector<int> path = {1, 2, 3, 4, 5, 4, 3, 2, 1, 2, 3, 4, 5};
  for (int d : path) step(d);  // the warm-up
  ca.own = cb.own = 0;
  g_allocations = 0;
  g_counting = true;
  for (int d : path) step(d);
  g_counting = false;
  EXPECT_GT(pair.points().size(), ties.size());  // contact points besides the ties
  EXPECT_GT(ca.own + cb.own, 0);                 // the count sees the models' resizes
  EXPECT_EQ(g_allocations.load() - ca.own - cb.own, 0);
}

}  // namespace
}  // namespace vdm
