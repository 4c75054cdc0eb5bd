// Once warmed up, a step allocates nothing: counted by wrapping glibc's malloc family.
// Built as its own executable (the wrapper would fight a sanitizer's allocator).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

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

}  // namespace
}  // namespace vdm
