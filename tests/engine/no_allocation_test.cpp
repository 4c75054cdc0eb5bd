// Once warmed up, a step allocates nothing: counted by wrapping glibc's malloc family.
// Built as its own executable (the wrapper would fight a sanitizer's allocator).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

#include "engine/contact.hpp"
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

}  // namespace
}  // namespace vdm
