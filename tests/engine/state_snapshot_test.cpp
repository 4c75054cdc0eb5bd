// State snapshots (resuming a run): a state saved after some steps and loaded into a fresh
// SimState continues bit for bit like the state that was never saved, with every solver, a
// refresh period, nonlinear iterations, gravity and halved steps; bad snapshots are refused.
#include <gtest/gtest.h>

#include <string>

#include "engine/state_snapshot.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

using scenario::build;

struct Case {
  SolverMethod method;
  int refresh_every, nonlinear_iterations;
  bool gravity;
  bool springs = false;
};

// Presses the cube's top a little further each step (step k), with a side force that
// changes every step (so the loads the halving fallback remembers matter too); with
// `springs`, per-node springs (as penalty contact sets them) pull one side's nodes instead,
// the same for two steps in a row (so the matrices of the step before are reused).
void load(const TissueModel& m, int k, StepInput& in, bool springs = false) {
  in.clear();
  scenario::press_top(m, 0.1, -0.003 * k, in);
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 0) > 0.05 - 1e-12) in.force(i, 0) = 0.01 * (k % 3);
  if (springs) {
    in.spring_k = NodeMat::Zero(m.n, 3);
    in.spring_u = NodeMat::Zero(m.n, 3);
    for (int i = 0; i < m.n; ++i)
      if (m.rest.positions(i, 1) > 0.05 - 1e-12) {
        in.spring_k(i, 1) = 50.0 * (1 + (k + 1) / 2);  // steps 7 and 8 alike
        in.spring_u(i, 1) = 0.001 * k;
      }
  }
}

// A fresh state loaded from a snapshot of `a` (the whole snapshot read).
SimState reloaded(const TissueModel& m, const SimState& a) {
  std::string bytes;
  save_state(m, a, bytes);
  SimState b = make_sim_state(m);
  size_t pos = 0;
  std::string error;
  EXPECT_TRUE(load_state(m, bytes, pos, b, error)) << error;
  EXPECT_EQ(pos, bytes.size());
  return b;
}

TEST(StateSnapshot, ALoadedStateContinuesBitForBit) {
  for (const Case& c : {Case{SolverMethod::structured, 1, 1, false}, Case{SolverMethod::structured, 3, 3, true},
                        Case{SolverMethod::reference, 1, 1, true}, Case{SolverMethod::reference, 2, 3, false},
                        Case{SolverMethod::direct, 1, 1, false}, Case{SolverMethod::direct, 3, 2, true},
                        Case{SolverMethod::structured, 3, 1, false, true}, Case{SolverMethod::direct, 2, 1, true, true}}) {
    const std::string what = std::string(to_string(c.method)) + " refresh " + std::to_string(c.refresh_every) +
                             " nonlinear " + std::to_string(c.nonlinear_iterations) + (c.springs ? " springs" : "");
    TissueDef def = scenario::cube_on_table(0.1, 5, c.method);
    def.solver.refresh_every = c.refresh_every;
    def.solver.nonlinear_iterations = c.nonlinear_iterations;
    def.use_gravity = c.gravity;
    const TissueModel m = build(def);
    SimState a = make_sim_state(m);
    StepInput in = make_step_input(m);
    for (int k = 1; k <= 7; ++k) {  // 7: not a multiple of the refresh periods
      load(m, k, in, c.springs);
      step(m, in, a);
    }
    std::string bytes;
    save_state(m, a, bytes);
    SimState b = make_sim_state(m);
    size_t pos = 0;
    std::string error;
    ASSERT_TRUE(load_state(m, bytes, pos, b, error)) << what << ": " << error;
    EXPECT_EQ(pos, bytes.size());
    EXPECT_EQ(b.u, a.u);
    EXPECT_EQ(b.step, a.step);
    for (int k = 8; k <= 14; ++k) {
      load(m, k, in, c.springs);
      step(m, in, a);
      step(m, in, b);
      ASSERT_FALSE(a.failed || b.failed) << what;
      ASSERT_EQ(b.u, a.u) << what << " step " << k;
      ASSERT_EQ(b.pressure, a.pressure) << what << " step " << k;
      EXPECT_EQ(b.stats.iterations, a.stats.iterations) << what << " step " << k;
      EXPECT_EQ(b.stats.total_refreshes, a.stats.total_refreshes) << what;
      EXPECT_EQ(b.stress, a.stress) << what;
    }
  }
}

// Without loads, and with the pressed nodes moving from step to step (one half of the top,
// then the other): the state that kept its right-hand side from step to step (only the
// entries the last pressed nodes moved written again, eliminate_rhs()) goes on bit for bit
// like the loaded one, whose right-hand side is made whole.
TEST(StateSnapshot, ALoadedStateContinuesBitForBitWithoutLoadsAsThePressedNodesMove) {
  for (const SolverMethod method : {SolverMethod::structured, SolverMethod::direct}) {
    const TissueModel m = build(scenario::cube_on_table(0.1, 5, method));
    auto press = [&](int k, StepInput& in) {
      in.clear();
      for (int i = 0; i < m.n; ++i)
        if (m.rest.positions(i, 2) > 0.05 - 1e-12 && (m.rest.positions(i, 0) < 0.0) == (k % 2 == 0)) {
          in.prescribed(i, 2) = 1;
          in.prescribed_u(i, 2) = -0.002 * k;
        }
    };
    SimState a = make_sim_state(m);
    StepInput in = make_step_input(m);
    in.force.resize(0, 3);  // no loads (as a scene without forces gives the step)
    in.pressure.resize(0);
    for (int k = 1; k <= 3; ++k) {
      press(k, in);
      step(m, in, a);
    }
    SimState b = reloaded(m, a);
    for (int k = 4; k <= 6; ++k) {
      press(k, in);
      step(m, in, a);
      step(m, in, b);
      ASSERT_FALSE(a.failed || b.failed);
      ASSERT_EQ(b.u, a.u) << to_string(method) << " step " << k;
      ASSERT_EQ(b.reaction, a.reaction) << to_string(method) << " step " << k;
    }
    EXPECT_LT(a.u.col(2).minCoeff(), -0.01);
  }
}

TEST(StateSnapshot, AHalvedStepAfterLoadingInterpolatesFromTheSavedLoads) {
  // The step after the snapshot is too large and done in halves: its forces interpolate from
  // the loads of the step before the snapshot, which the snapshot carries.
  const TissueModel m = build(scenario::clamped_beam(0.1, 0.02, 10, 2));
  StepInput in = make_step_input(m);
  auto pull = [&](double newton) {
    in.force.setZero();
    for (int i = 0; i < m.n; ++i)
      if (m.rest.positions(i, 1) > 0.1 - 1e-12) in.force(i, 1) = newton / 9;
  };
  SimState a = make_sim_state(m);
  pull(10);
  step(m, in, a);
  SimState b = reloaded(m, a);
  pull(400);
  step(m, in, a);
  step(m, in, b);
  ASSERT_NE(a.stats.fallback, nullptr);
  EXPECT_NE(std::string(a.stats.fallback).find("load increment"), std::string::npos);
  EXPECT_EQ(b.u, a.u);
  EXPECT_EQ(b.stats.fallbacks, a.stats.fallbacks);
}

TEST(StateSnapshot, SavedStateOnlyIsNotEnough) {
  // Why the snapshot carries the engine's warm starts and refresh geometry: copying the
  // state's own arrays into a fresh SimState drifts from the run (iterative warm starts,
  // the geometry of the last refresh), which a resume must not.
  TissueDef def = scenario::cube_on_table(0.1, 5, SolverMethod::structured);
  def.solver.refresh_every = 3;
  const TissueModel m = build(def);
  SimState a = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= 7; ++k) {
    load(m, k, in);
    step(m, in, a);
  }
  SimState b = make_sim_state(m);
  b.u = a.u;
  b.x = a.x;
  b.velocity = a.velocity;
  b.pressure = a.pressure;
  b.step = a.step;
  b.time = a.time;
  load(m, 8, in);
  step(m, in, a);
  step(m, in, b);
  EXPECT_NE(b.u, a.u);
}

TEST(StateSnapshot, ABadSnapshotIsRefused) {
  const TissueModel m = build(scenario::cube_on_table(0.1, 4));
  SimState a = make_sim_state(m);
  StepInput in = make_step_input(m);
  load(m, 1, in);
  step(m, in, a);
  std::string bytes;
  save_state(m, a, bytes);
  std::string error;
  for (size_t cut : {size_t(0), size_t(7), size_t(40), bytes.size() / 2, bytes.size() - 1}) {
    SimState b = make_sim_state(m);
    size_t pos = 0;
    EXPECT_FALSE(load_state(m, std::string_view(bytes).substr(0, cut), pos, b, error)) << cut;
    EXPECT_NE(error.find("state snapshot"), std::string::npos) << error;
  }
  const TissueModel other = build(scenario::cube_on_table(0.1, 5));
  SimState c = make_sim_state(other);
  size_t pos = 0;
  EXPECT_FALSE(load_state(other, bytes, pos, c, error));
  EXPECT_NE(error.find("another number of nodes"), std::string::npos) << error;
  TissueDef direct_def = scenario::cube_on_table(0.1, 4, SolverMethod::direct);
  const TissueModel direct = build(direct_def);
  SimState d = make_sim_state(direct);
  pos = 0;
  EXPECT_FALSE(load_state(direct, bytes, pos, d, error));
  EXPECT_NE(error.find("another solver"), std::string::npos) << error;
}

}  // namespace
}  // namespace vdm
