// Halved load increments (issue 7, solver trouble): a step that cannot be done whole is done
// in halves (down to 1/8), counts as one step, and says so; a step that cannot be done even
// then fails cleanly. Each case compares with the same loading done in explicit steps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <tuple>

#include "engine/step_workspace.hpp"
#include "support/hard_cases.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

using scenario::build;

constexpr double kLength = 0.1, kWidth = 0.02;

TissueModel beam(int nonlinear_iterations = 1) {
  TissueDef def = scenario::clamped_beam(kLength, kWidth, 10, 2);
  // The mechanism's bounds below were measured with the paper's capsule on this beam of two
  // cells across (the membrane's, softer on it, folds at a threefold stretch in one step).
  def.capsule = CapsuleForm::paper;
  def.solver.nonlinear_iterations = nonlinear_iterations;
  return build(def);
}

// Stretches the beam's free end to `stretch` x length in `steps` equal steps.
SimState stretched(const TissueModel& m, double stretch, int steps) {
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int k = 1; k <= steps; ++k) {
    scenario::move_end(m, kLength, Vec3(0, stretch * kLength * k / steps, 0), in);
    step(m, in, s);
    EXPECT_FALSE(s.failed) << s.failure;
  }
  return s;
}

double max_abs(const NodeMat& a) { return a.cwiseAbs().maxCoeff(); }

TEST(LoadHalving, AStepTooLargeIsDoneInHalvesAndMatchesExplicitSteps) {
  // Pulling a beam to three times its length in one step: the single linearised update
  // turns the surface inside out near the clamp, and the volume corrections cannot bring
  // the volume back (before this fallback the step was kept with the volume 85 % off).
  const TissueModel m = beam();
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::move_end(m, kLength, Vec3(0, 2.0 * kLength, 0), in);
  step(m, in, s);
  ASSERT_FALSE(s.failed) << s.failure;
  EXPECT_EQ(s.step, 1);
  EXPECT_DOUBLE_EQ(s.time, m.dt);
  EXPECT_GE(s.stats.fallbacks, 1);
  ASSERT_NE(s.stats.fallback, nullptr);
  EXPECT_NE(std::string(s.stats.fallback).find("done in halves of the load increment"), std::string::npos)
      << s.stats.fallback;
  EXPECT_EQ(s.stats.total_fallbacks, s.stats.fallbacks);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_EQ(s.warnings.back(), s.stats.fallback);
  hard::expect_sensible(m, s, 0.2 + 1e-12, "stretch to 3x in one step");
  EXPECT_LE(std::abs(s.volume_rel_error), 1e-4);
  EXPECT_LE(s.u.col(1).maxCoeff(), 0.2 + 1e-12);
  // The free end is exactly where it was sent; velocity is that of the whole step.
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 1) > kLength - 1e-12) {
      EXPECT_EQ(s.u(i, 1), 0.2);
    }
  EXPECT_LT(max_abs(s.velocity - s.u / m.dt), 1e-9 * max_abs(s.u) / m.dt);

  // The same as two explicit half steps (it is that computation).
  const SimState two = stretched(m, 2.0, 2);
  EXPECT_EQ(two.stats.fallbacks, 0) << "each half alone is fine";
  // (Equal to the solves' tolerance, 1e-10, not bit for bit: the discarded whole-step
  // attempt leaves the iterative solver other warm starts.)
  EXPECT_LT(max_abs(s.u - two.u), 1e-9 * max_abs(two.u));
  // And close to the stretch done in many small steps. Each step linearises at its start
  // geometry, so the result depends on the step size; measured against 16 steps, the largest
  // difference (relative to the largest displacement) is 2.6 % for 2 steps, 0.45 % for 4 and
  // 0.16 % for 8: converging. Held to 4 % (the 2-step figure with 50 % margin), and 4 explicit
  // steps must be closer still. (From about 64 steps on, this 300 % stretch settles on another
  // branch, a different neck: mid-span necking 3.7 mm instead of 4.8 mm.)
  const SimState fine = stretched(m, 2.0, 16), four = stretched(m, 2.0, 4);
  const double err = max_abs(s.u - fine.u) / max_abs(fine.u);
  EXPECT_LT(err, 0.04) << "halved step against 16 steps";
  EXPECT_LT(max_abs(four.u - fine.u) / max_abs(fine.u), err) << "4 steps against 16";
  const int mid = nearest_node(m.rest.positions, Vec3(kWidth / 2, kLength / 2, 0));
  EXPECT_LT(s.u(mid, 0), 0.0) << "the middle necks";
  EXPECT_NEAR(s.u(mid, 0), fine.u(mid, 0), 0.04 * std::abs(fine.u(mid, 0)));
}

TEST(LoadHalving, HalvesAreHalvedAgainDownToAnEighth) {
  // Five and nine times the length in one step: halves are not enough, quarters and eighths
  // are; each equals the same number of explicit steps.
  const TissueModel m = beam();
  for (const auto& [stretch, parts, text] : {std::make_tuple(4.0, 4, "down to 1/4"), std::make_tuple(8.0, 8, "down to 1/8")}) {
    SimState s = make_sim_state(m);
    StepInput in = make_step_input(m);
    scenario::move_end(m, kLength, Vec3(0, stretch * kLength, 0), in);
    step(m, in, s);
    ASSERT_FALSE(s.failed) << s.failure;
    ASSERT_NE(s.stats.fallback, nullptr);
    EXPECT_NE(std::string(s.stats.fallback).find(text), std::string::npos) << s.stats.fallback;
    EXPECT_EQ(s.step, 1);
    hard::expect_sensible(m, s, stretch * kLength + 1e-12, "stretch " + std::to_string(stretch), false);
    const SimState e = stretched(m, stretch, parts);
    EXPECT_EQ(e.stats.total_fallbacks, 0);
    EXPECT_LT(max_abs(s.u - e.u), 1e-9 * max_abs(e.u)) << stretch;
  }
}

TEST(LoadHalving, AStepThatCannotBeDoneEvenInEighthsFailsAndChangesNothing) {
  // A corrupted model no increment can help (every solver gets NaN): after the direct
  // fallback and halving down to 1/8 the step fails, the state as it was.
  TissueDef def = scenario::cube_on_table(0.1, 4);
  TissueModel m = build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, 0.1, -0.005, in);
  step(m, in, s);
  ASSERT_FALSE(s.failed);
  const NodeMat u = s.u, x = s.x, v = s.velocity;
  const double p = s.pressure, t = s.time;
  m.bulk(3, 0) = std::nan("");
  scenario::press_top(m, 0.1, -0.01, in);
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("no solver could solve the step"), std::string::npos) << s.failure;
  EXPECT_NE(s.failure.find("also in parts of 1/8 of the load increment"), std::string::npos) << s.failure;
  EXPECT_EQ(s.step, 1);
  EXPECT_EQ(s.time, t);
  EXPECT_EQ(s.u, u);
  EXPECT_EQ(s.x, x);
  EXPECT_EQ(s.velocity, v);
  EXPECT_EQ(s.pressure, p);
  EXPECT_FALSE(s.stats.converged);
  // The model mended, the same input goes through.
  m.bulk(3, 0) = m.bulk(4, 0);
  step(m, in, s);
  EXPECT_FALSE(s.failed) << s.failure;
  EXPECT_EQ(s.step, 2);
}

TEST(LoadHalving, ForcesAreInterpolatedFromTheLastStepsLoads) {
  // A beam pulled by end forces: a step to a force far too large for one linearised update,
  // after a first step with a small force. The halves interpolate the force between the two
  // steps' inputs, so the halved step equals explicit steps with those interpolated forces.
  const TissueModel m = beam();
  StepInput in = make_step_input(m);
  auto pull = [&](double newton) {
    in.force.setZero();
    int ends = 0;
    for (int i = 0; i < m.n; ++i) ends += m.rest.positions(i, 1) > kLength - 1e-12;
    for (int i = 0; i < m.n; ++i)
      if (m.rest.positions(i, 1) > kLength - 1e-12) in.force(i, 1) = newton / ends;
  };
  // Find a force the single step cannot take: doubling until the fallback appears (400 N,
  // an eightfold stretch: folds, so the shape check below leaves them out).
  double big = 0;
  for (double f = 50; f < 1e6 && big == 0; f *= 2) {
    SimState probe = make_sim_state(m);
    pull(10);
    step(m, in, probe);
    pull(f);
    step(m, in, probe);
    ASSERT_FALSE(probe.failed) << probe.failure;
    if (probe.stats.fallback && std::string(probe.stats.fallback).find("load increment") != std::string::npos) big = f;
  }
  ASSERT_GT(big, 0) << "no force found that needs halving";
  SimState s = make_sim_state(m);
  pull(10);
  step(m, in, s);
  pull(big);
  step(m, in, s);
  ASSERT_FALSE(s.failed) << s.failure;
  hard::expect_sensible(m, s, 10 * kLength, "pulled by " + std::to_string(big) + " N", false);
  // Explicit steps at the force fractions the fallback used: 10 + (big - 10) * k / parts.
  ASSERT_NE(std::string(s.stats.fallback).find("done in halves"), std::string::npos) << s.stats.fallback;
  EXPECT_EQ(s.step, 2);
  SimState e = make_sim_state(m);
  pull(10);
  step(m, in, e);
  for (int k = 1; k <= 2; ++k) {
    pull(10 + (big - 10) * k / 2.0);
    step(m, in, e);
  }
  EXPECT_EQ(e.stats.total_fallbacks, 0);
  EXPECT_LT(max_abs(s.u - e.u), 1e-9 * max_abs(e.u)) << big << " N";
}

TEST(LoadHalving, RewindAfterAHalvedStepGoesBackToTheWholeStepsStart) {
  // Contact re-solves a step after rewind_step(): after a halved step that must restore the
  // state before the whole step (not before its last half), and a re-solve gives the same.
  TissueDef def = scenario::clamped_beam(kLength, kWidth, 10, 2);
  def.solver.refresh_every = 2;
  def.use_gravity = true;
  const TissueModel m = build(def);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::move_end(m, kLength, Vec3(0, 0.02, 0), in);
  step(m, in, s);
  const NodeMat u0 = s.u;
  const double p0 = s.pressure;
  scenario::move_end(m, kLength, Vec3(0, 0.2, 0), in);
  step(m, in, s);
  ASSERT_FALSE(s.failed) << s.failure;
  ASSERT_NE(s.stats.fallback, nullptr);
  // What the contact reads for a node's start position (X + the rewind point's u): the whole
  // step's start, and positions X + u bit for bit after the parts.
  EXPECT_EQ(s.work->start.u, u0);
  const NodeMat x = m.rest.positions + s.u;
  EXPECT_EQ(std::memcmp(x.data(), s.x.data(), sizeof(double) * size_t(x.size())), 0);
  const NodeMat u_once = s.u;
  rewind_step(m, s);
  EXPECT_EQ(s.step, 1);
  EXPECT_EQ(s.u, u0);
  EXPECT_EQ(s.pressure, p0);
  step(m, in, s);
  ASSERT_FALSE(s.failed) << s.failure;
  EXPECT_EQ(s.step, 2);
  EXPECT_LT(max_abs(s.u - u_once), 1e-9 * max_abs(u_once));
}

}  // namespace
}  // namespace vdm
