// Elastic core snapshots (resuming a run): a core state saved between steps and loaded into a
// fresh one continues bit for bit like the state that was never saved: with entries held by
// multipliers through a factor kept across steps, with a prescribed set large enough to be
// factorised, and with inertia; the loaded state factorises no more than the saved one would.
// Truncated, foreign or inconsistent bytes are refused with a message.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "engine/core/core_snapshot.hpp"
#include "engine/shapes.hpp"
#include "support/free_input.hpp"
#include "support/held_below.hpp"

namespace vdm::core {
namespace {

// A ball held at its base on every axis and on z in a ring above it (x and y share a factor, z
// has its own), cell `h`.
CoreModel ball(double h, int max_held = CoreSettings{}.max_held, bool inertia = false) {
  const SurfaceMesh s = make_icosphere(0.04, 4);
  CoreDef def;
  def.surface = s;
  def.young_modulus = 3000;
  def.cell_size = h;
  def.fixed = test::held_below(s, -0.035);
  for (int i = 0; i < s.node_count(); ++i)
    if (s.positions(i, 2) < -0.03) def.fixed(i, 2) = 1;
  def.settings.max_held = max_held;
  def.use_inertia = def.use_gravity = inertia;
  def.dt = 0.01;
  def.damping = 2;
  CoreModel m;
  std::string error;
  EXPECT_TRUE(build_core_model(def, m, error)) << error;
  return m;
}

// Step k's input: a cap of the ball's top pressed down and a little sideways, growing to step
// 4, back to step 2's at step 5 (entries released), step 4's again at step 6; a side force on
// one free node that changes every step.
void press(const CoreModel& m, int k, StepInput& in) {
  const int depth = k == 5 ? 2 : k == 6 ? 4 : k;
  in.prescribed.setZero();
  in.prescribed_u.setZero();
  in.force.setZero();
  for (int i = 0; i < m.ns; ++i)
    if (m.surface.positions(i, 2) > 0.039 - 0.0005 * depth) {
      in.prescribed.row(i).setOnes();
      in.prescribed_u.row(i) = Vec3(0.0002 * k, 0, -0.002 * depth).transpose();
    }
  in.force(0, 0) = 0.002 * (k % 3);
}

// Steps 1 to `steps` of the press from the state `a` (just made); whether each converged.
bool pressed(const CoreModel& m, int steps, StepInput& in, CoreState& a) {
  bool converged = true;
  for (int k = 1; k <= steps; ++k) {
    press(m, k, in);
    step(m, in, a);
    converged = converged && a.stats.converged;
  }
  return converged;
}

// A fresh state loaded from a snapshot of `a` (the whole snapshot read).
CoreState reloaded(const CoreModel& m, const CoreState& a) {
  std::string bytes;
  save_core_state(m, a, bytes);
  CoreState b = make_core_state(m);
  size_t pos = 0;
  std::string error;
  EXPECT_TRUE(load_core_state(m, bytes, pos, b, error)) << error;
  EXPECT_EQ(pos, bytes.size());
  return b;
}

// Steps `a` and `b` on from step `first` to `last` with the same inputs: the same bits, and the
// same number of factorisations, at every step.
void expect_same_steps(const CoreModel& m, CoreState& a, CoreState& b, int first, int last, bool pressed) {
  StepInput in = test::free_input(m.ns);
  for (int k = first; k <= last; ++k) {
    if (pressed) press(m, k, in);
    step(m, in, a);
    step(m, in, b);
    ASSERT_TRUE(a.stats.converged) << "step " << k;
    EXPECT_EQ(b.u, a.u) << "step " << k;
    EXPECT_EQ(b.v, a.v) << "step " << k;
    EXPECT_EQ(b.reaction, a.reaction) << "step " << k;
    EXPECT_EQ(b.pressure, a.pressure) << "step " << k;
    EXPECT_EQ(b.volume, a.volume) << "step " << k;
    EXPECT_EQ(b.stats.iterations, a.stats.iterations) << "step " << k;
    EXPECT_EQ(b.stats.factorizations, a.stats.factorizations) << "step " << k;
  }
}

TEST(CoreSnapshot, HeldEntriesThroughAKeptFactorContinueBitForBit) {
  // The default max_held: the cap is held by multipliers through the factor of the first
  // step, whose columns grow step by step; after the load nothing is factorised again.
  const CoreModel m = ball(0.008);
  CoreState a = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  ASSERT_TRUE(pressed(m, 3, in, a));
  // What the snapshot must carry is there: held entries with their factor, a factor for x
  // and y and one for z, and columns solved in more than one group.
  const CoreCarry carry = core_carry(a);
  ASSERT_GT(carry.held, 0);
  ASSERT_TRUE(carry.held_factored);
  ASSERT_EQ(carry.factors, 2);
  ASSERT_GT(carry.column_solves, 2);
  CoreState b = reloaded(m, a);
  expect_same_steps(m, a, b, 4, 6, true);
  EXPECT_EQ(a.stats.factorizations + b.stats.factorizations, 0) << "step 6 reuses the factors";
}

TEST(CoreSnapshot, AFactorisedPrescribedSetContinuesBitForBit) {
  // A max_held below the cap's entries: the cap is factorised with them, and partly released
  // at step 5 (the factors made again for the smaller cap).
  const CoreModel m = ball(0.008, 12);
  CoreState a = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  ASSERT_TRUE(pressed(m, 3, in, a));
  ASSERT_NE(core_carry(a).factored, m.fixed) << "the cap is in the factor";
  CoreState b = reloaded(m, a);
  expect_same_steps(m, a, b, 4, 6, true);
}

TEST(CoreSnapshot, InertiaContinuesBitForBit) {
  // Under its weight with inertia (the lattice's velocity and implicit Euler's load), pressed
  // from step 2 on.
  const CoreModel m = ball(0.008, CoreSettings{}.max_held, true);
  CoreState a = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  for (int k = 1; k <= 3; ++k) {
    if (k > 1) press(m, k, in);
    step(m, in, a);
    ASSERT_TRUE(a.stats.converged);
  }
  ASSERT_GT(a.velocity.cwiseAbs().maxCoeff(), 0.0);
  CoreState b = reloaded(m, a);
  expect_same_steps(m, a, b, 4, 6, true);
}

// Where the factors' part and the held entries' part of a core snapshot of `m` start, walked
// through its layout (core_snapshot.cpp): a header of 48 bytes; nine arrays (rows, columns,
// then the values), the rewound flag, three numbers and the warnings; the quaternions; the
// two masks; per factor slot three flags and two lists of 32-bit integers (its columns' nodes
// and the groups they were solved in); then the held entries.
struct Layout {
  size_t factors = 0, held = 0, c0 = 0;  // c0: the held entries' compliance's values
};
Layout layout(const CoreModel& m, const std::string& bytes) {
  auto count = [&](size_t where) {
    std::int64_t v = 0;
    std::memcpy(&v, bytes.data() + where, sizeof v);
    return static_cast<size_t>(v);
  };
  size_t at = 48;
  for (int k = 0; k < 9; ++k) at += 16 + 24 * count(at);
  at += 8 + 24;
  const size_t warnings = count(at);
  at += 8;
  for (size_t k = 0; k < warnings; ++k) at += 8 + count(at);
  at += 8 + 32 * count(at);
  at += 2 * (16 + 3 * static_cast<size_t>(m.ns));
  Layout l;
  l.factors = at;
  for (int k = 0; k < 3; ++k) {
    at += 24;
    at += 8 + 4 * count(at);
    at += 8 + 4 * count(at);
  }
  l.held = at;
  const size_t held = count(at);
  l.c0 = at + 2 * (8 + 4 * held) + 8 + 16;
  return l;
}

TEST(CoreSnapshot, TruncatedForeignOrInconsistentBytesAreRefused) {
  const CoreModel m = ball(0.008);
  CoreState a = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  pressed(m, 2, in, a);
  std::string bytes;
  save_core_state(m, a, bytes);
  auto refusal = [&](const CoreModel& model, std::string_view data) {
    CoreState b = make_core_state(model);
    size_t pos = 0;
    std::string error;
    EXPECT_FALSE(load_core_state(model, data, pos, b, error));
    return error;
  };
  const std::string_view all(bytes);
  for (size_t cut : {size_t(0), size_t(5), size_t(8), size_t(60), bytes.size() / 3, bytes.size() / 2,
                     bytes.size() - 9, bytes.size() - 1})
    EXPECT_EQ(refusal(m, all.substr(0, cut)).rfind("state snapshot: the elastic core's", 0), 0u) << "cut at " << cut;
  // Of another lattice: a finer cell.
  EXPECT_NE(refusal(ball(0.007), all).find("of another lattice"), std::string::npos);
  // Not a core snapshot at all.
  EXPECT_NE(refusal(m, std::string(bytes.size(), 'x')).find("missing"), std::string::npos);
  // Inconsistent parts, under bytes that are there: an axis on a slot after its own, a
  // column's lattice node beyond the lattice, a held entry's node beyond the surface.
  const Layout at = layout(m, bytes);
  auto with = [&](size_t where, auto value) {
    std::string spoilt = bytes;
    std::memcpy(&spoilt[where], &value, sizeof value);
    return refusal(m, spoilt);
  };
  EXPECT_NE(with(at.factors + 8, std::int64_t{1}).find("factors are truncated or damaged"), std::string::npos);
  EXPECT_NE(with(at.factors + 32, std::int32_t{m.ng}).find("factors are truncated or damaged"), std::string::npos);
  EXPECT_NE(with(at.held + 8, std::int32_t{m.ns}).find("held entries are truncated or damaged"), std::string::npos);
  // Any word of the factors' part and of the held entries' lists set to all ones: refused or
  // read, never a read or write out of bounds (the sanitizer pass runs this too).
  for (size_t where = at.factors; where < at.c0; where += 8) {
    std::string spoilt = bytes;
    std::memset(&spoilt[where], 0xff, 8);
    CoreState b = make_core_state(m);
    size_t pos = 0;
    std::string error;
    if (!load_core_state(m, spoilt, pos, b, error)) {
      EXPECT_EQ(error.rfind("state snapshot: ", 0), 0u) << where;
    }
  }
}

}  // namespace
}  // namespace vdm::core
