// Solver trouble (issue 7): a non-converged iterative solve falls back to the direct solver
// and says so; a step no solver can do, or malformed input, fails cleanly; a re-solved step
// (rewind_step) equals a step solved once; gravity between refreshes uses one geometry.
#include <gtest/gtest.h>

#include <cmath>

#include "support/scenarios.hpp"

namespace vdm {
namespace {

using scenario::build;

TissueModel pressed_cube_model(SolverMethod method, int max_iterations) {
  TissueDef def = scenario::cube_on_table(0.1, 5, method);
  def.solver.max_iterations = max_iterations;
  return build(def);
}

TEST(SolverTrouble, NonConvergedIterativeSolvesFallBackToTheDirectSolver) {
  const double L = 0.1;
  const TissueModel direct = pressed_cube_model(SolverMethod::direct, 2000);
  for (SolverMethod method : {SolverMethod::structured, SolverMethod::reference}) {
    const TissueModel m = pressed_cube_model(method, 1);  // one Krylov iteration: never converges
    SimState s = make_sim_state(m), ref = make_sim_state(direct);
    StepInput in = make_step_input(m);
    for (int k = 1; k <= 5; ++k) {
      scenario::press_top(m, L, -0.004 * k, in);
      step(m, in, s);
      step(direct, in, ref);
      ASSERT_FALSE(s.failed) << s.failure;
      EXPECT_EQ(s.stats.fallbacks, 1) << to_string(method) << " step " << k;
      ASSERT_NE(s.stats.fallback, nullptr);
      EXPECT_NE(std::string(s.stats.fallback).find("did not converge"), std::string::npos);
      EXPECT_TRUE(s.stats.converged);
      EXPECT_LT((s.u - ref.u).cwiseAbs().maxCoeff(), 1e-9 * ref.u.cwiseAbs().maxCoeff()) << to_string(method);
    }
    EXPECT_EQ(s.stats.total_fallbacks, 5);
    EXPECT_FALSE(s.warnings.empty());
  }
}

TEST(SolverTrouble, ConvergedSolvesDoNotFallBack) {
  const TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, 0.1, -0.01, in);
  step(m, in, s);
  EXPECT_EQ(s.stats.fallbacks, 0);
  EXPECT_EQ(s.stats.fallback, nullptr);
}

TEST(SolverTrouble, AStepThatNoSolverCanDoFailsCleanlyAndChangesNothing) {
  TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, 0.1, -0.005, in);
  step(m, in, s);
  ASSERT_FALSE(s.failed);
  const NodeMat u = s.u;
  const double p = s.pressure;
  m.bulk(3, 0) = std::nan("");  // a corrupted model: every solver gets NaN
  scenario::press_top(m, 0.1, -0.01, in);
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("no solver"), std::string::npos) << s.failure;
  EXPECT_EQ(s.step, 1);
  EXPECT_EQ(s.u, u);
  EXPECT_EQ(s.pressure, p);
}

TEST(SolverTrouble, MalformedInputFailsTheStepWithAReason) {
  const TissueModel m = pressed_cube_model(SolverMethod::structured, 2000);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  in.prescribed(5, 2) = 1;
  in.prescribed_u(5, 2) = std::nan("");
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("prescribed_u is not finite"), std::string::npos) << s.failure;
  EXPECT_EQ(s.step, 0);
  in.prescribed_u = NodeMat::Zero(3, 3);  // wrong size (used to be read out of bounds)
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("prescribed_u has the wrong number of rows"), std::string::npos) << s.failure;
  in = make_step_input(m);
  step(m, in, s);
  EXPECT_FALSE(s.failed) << "a good input clears the failure";
  EXPECT_TRUE(s.failure.empty());
}

// Step k of the cube press twice side by side: `a` solves it once; `b` first tries another
// input (a deeper press), rewinds, then solves the real one (what the contact's active set does).
void step_once_and_after_a_rewind(const TissueModel& m, double L, int k, StepInput& in, StepInput& other, SimState& a,
                                  SimState& b) {
  scenario::press_top(m, L, -0.003 * k, in);
  scenario::press_top(m, L, -0.02, other);
  step(m, in, a);
  step(m, other, b);  // a different attempt first...
  rewind_step(m, b);
  step(m, in, b);  // ...then the real one
}

TEST(Rewind, ResolvingAStepGivesTheSameStateAsSolvingItOnce) {
  // With a refresh period and nonlinear iterations, the geometry, matrices and refresh
  // counter are part of what a re-solve must restore (contact's active set re-solves).
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 4);
  def.solver.refresh_every = 3;
  def.solver.nonlinear_iterations = 3;
  def.use_gravity = true;
  const TissueModel m = build(def);
  SimState a = make_sim_state(m), b = make_sim_state(m);
  StepInput in = make_step_input(m), other = make_step_input(m);
  for (int k = 1; k <= 7; ++k) {
    step_once_and_after_a_rewind(m, L, k, in, other, a, b);
    EXPECT_EQ(a.step, b.step);
    // Equal up to the iterative solver's tolerance (its warm starts differ).
    EXPECT_LT((a.u - b.u).cwiseAbs().maxCoeff(), 1e-9 * L) << "step " << k;
    EXPECT_LT((a.area_vectors - b.area_vectors).cwiseAbs().maxCoeff(), 1e-9 * a.area_vectors.cwiseAbs().maxCoeff())
        << "step " << k;
    EXPECT_EQ(a.stats.refreshed, b.stats.refreshed) << "step " << k;
  }
}

TEST(Rewind, ARedoAtTheStepsStartReusesItsGeometryExactly) {
  // Refreshing every step: the first attempt built the geometry at the step's start, a redo
  // after rewind_step() starts there again and does not rebuild it (the contact redoes about
  // one step in six). With the direct solver the result is that of a single solve bit for bit.
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 4);
  def.solver.method = SolverMethod::direct;
  const TissueModel m = build(def);
  SimState a = make_sim_state(m), b = make_sim_state(m);
  StepInput in = make_step_input(m), other = make_step_input(m);
  for (int k = 1; k <= 5; ++k) {
    step_once_and_after_a_rewind(m, L, k, in, other, a, b);
    EXPECT_TRUE(b.stats.refreshed);
    // b's other attempts refreshed once a step; the first redo too (a first step's rewind
    // leaves no geometry), the later ones not.
    EXPECT_EQ(a.stats.total_refreshes, k);
    EXPECT_EQ(b.stats.total_refreshes, k + 1) << "step " << k;
    EXPECT_EQ(a.u, b.u) << "step " << k;
    EXPECT_EQ(a.pressure, b.pressure) << "step " << k;
    EXPECT_EQ(a.reaction, b.reaction) << "step " << k;
    EXPECT_EQ(a.volume, b.volume) << "step " << k;
  }
}

TEST(Refresh, BetweenRefreshesGravityUsesOneGeometry) {
  // Loads between refreshes come from the refresh's surface (area vectors and depths): the
  // hydrostatic load is then exactly the weight of that surface's volume, so a hung organ's
  // steady state does not depend on which step of the period it is measured at.
  TissueDef def = default_tissue(make_icosphere(0.05, 3));
  def.use_gravity = true;
  def.connectivity_modulus = 200;
  def.bulk = 2000;
  def.solver.refresh_every = 1000;  // never after the first
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  const StepInput in = make_step_input(m);
  step(m, in, s);
  const NodeMat u1 = s.u;
  for (int k = 0; k < 5; ++k) step(m, in, s);
  // The matrix, the loads and the volume row are all at the rest geometry: the same system,
  // up to the Newton term of the volume row (second order).
  EXPECT_LT((s.u - u1).cwiseAbs().maxCoeff(), 1e-3 * u1.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace vdm
