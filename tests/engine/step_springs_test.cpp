// Per-node, per-axis springs in the step (StepInput::spring_k, spring_u): solved implicitly,
// the same by every solver, and a prescribed displacement in the stiff limit.
#include <gtest/gtest.h>

#include "support/scenarios.hpp"

namespace vdm {
namespace {

// The cube's top face pulled up by springs of stiffness k toward u_z = travel.
StepInput springs_on_top(const TissueModel& m, double L, double k, double travel) {
  StepInput in = make_step_input(m);
  in.spring_k = NodeMat::Zero(m.n, 3);
  in.spring_u = NodeMat::Zero(m.n, 3);
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 2) > L / 2 - 1e-12) {
      in.spring_k(i, 2) = k;
      in.spring_u(i, 2) = travel;
    }
  return in;
}

TEST(StepSprings, EverySolverAgrees) {
  const double L = 0.1;
  NodeMat results[3];
  const SolverMethod methods[3] = {SolverMethod::reference, SolverMethod::structured, SolverMethod::direct};
  for (int k = 0; k < 3; ++k) {
    const TissueModel m = scenario::build(scenario::cube_on_table(L, 5, methods[k]));
    SimState s = make_sim_state(m);
    step(m, springs_on_top(m, L, 50.0, -0.01), s);
    ASSERT_FALSE(s.failed) << s.failure;
    EXPECT_LT(std::abs(s.volume_rel_error), 1e-6);
    results[k] = s.u;
  }
  const double scale = results[2].cwiseAbs().maxCoeff();
  EXPECT_GT(scale, 1e-4);  // the springs did move the cube
  EXPECT_LT((results[0] - results[2]).cwiseAbs().maxCoeff(), 1e-6 * scale);
  EXPECT_LT((results[1] - results[2]).cwiseAbs().maxCoeff(), 1e-6 * scale);
}

TEST(StepSprings, StiffSpringsTendToThePrescribedDisplacement) {
  const double L = 0.1, travel = -0.01;
  const TissueModel m = scenario::build(scenario::cube_on_table(L, 5, SolverMethod::direct));
  SimState prescribed = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, L, travel, in);
  step(m, in, prescribed);
  double last = 1e300;
  for (double k : {1e2, 1e4, 1e6}) {
    SimState s = make_sim_state(m);
    step(m, springs_on_top(m, L, k, travel), s);
    ASSERT_FALSE(s.failed) << s.failure;
    const double gap = (s.u - prescribed.u).cwiseAbs().maxCoeff();
    EXPECT_LT(gap, 0.5 * last) << k;
    last = gap;
  }
  EXPECT_LT(last, 1e-3 * std::abs(travel));
}

TEST(StepSprings, BadSpringsAreRejected) {
  const TissueModel m = scenario::build(scenario::cube_on_table(0.1, 3));
  SimState s = make_sim_state(m);
  StepInput in = springs_on_top(m, 0.1, 10.0, 0.0);
  in.spring_k(0, 0) = -1.0;
  step(m, in, s);
  EXPECT_TRUE(s.failed);
  EXPECT_NE(s.failure.find("spring_k"), std::string::npos) << s.failure;
  in = springs_on_top(m, 0.1, 10.0, 0.0);
  in.spring_u.resize(3, 3);
  step(m, in, s);
  EXPECT_TRUE(s.failed);
}

}  // namespace
}  // namespace vdm
