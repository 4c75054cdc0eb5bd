// The step's results pass (one gather over the neighbour lists) against the plain kernels it
// replaced: K u by the edge-list product, the residual and reaction loop written out entry by
// entry, and compute_strain_stress().
#include <gtest/gtest.h>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/step_results.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stiffness.hpp"
#include "engine/stress.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

// What the pass must give, the plain way: reactions and contact pressures written into `s`
// (compute_strain_stress reads the reactions), the sums returned.
ResidualSums plain_results(const TissueModel& m, const StepResultsInput& in, SimState& s, NodeMat& Ku) {
  Ku.resize(m.n, 3);
  multiply(m.pattern, in.K, s.u, Ku);
  ResidualSums sums;
  for (int i = 0; i < m.n; ++i) {
    bool any = false;
    for (int d = 0; d < 3; ++d) {
      double base = Ku(i, d) - s.pressure * s.area_vectors(i, d);
      if (in.force) base -= (*in.force)(i, d);
      double free_r = base;
      if (in.springs) free_r += (*in.springs)(i, d) * s.u(i, d);
      const bool held = in.mask(i, d) != 0;
      any = any || held;
      s.reaction(i, d) = held ? base : 0.0;
      if (!held) sums.free2[d] += free_r * free_r;
      sums.rhs2[d] += in.rhs(i, d) * in.rhs(i, d);
      sums.volume_row[d] += in.a_free(i, d) * s.u(i, d);
    }
    const double an = in.area_norms[i];
    s.reaction_pressure[i] = any && an > 0 ? s.reaction.row(i).norm() / an : 0.0;
  }
  if (m.compute_stress) {
    std::vector<double> scratch(3 * size_t(m.n));
    compute_strain_stress(m, s, scratch.data());
  }
  return sums;
}

// |a - b| within `rel` of b's largest entry, entry by entry.
::testing::AssertionResult close(const NodeMat& a, const NodeMat& b, double rel) {
  const double tol = rel * b.cwiseAbs().maxCoeff();
  const double diff = (a - b).cwiseAbs().maxCoeff();
  if (diff <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max difference " << diff << " > " << tol;
}

// A pressed cube with an infinite B along x on some nodes (their stress from the reaction),
// loads and springs: every case of the pass (loads, springs, stress or not, no capsule term)
// against the plain kernels on the state after the steps.
TEST(StepResults, MatchThePlainProductResidualLoopAndStress) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 4);
  const int n = def.mesh.node_count();
  def.bulk_modulus = NodeMat::Constant(n, 3, 20000.0);
  for (int i = 0; i < n; i += 3) def.bulk_modulus(i, 0) = std::numeric_limits<double>::infinity();
  def.bulk_modulus(1, 1) = def.bulk_modulus(1, 2) = std::numeric_limits<double>::infinity();
  TissueModel m = scenario::build(def);
  ASSERT_FALSE(m.infinite_nodes.empty());
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  in.spring_k = NodeMat::Zero(m.n, 3);
  in.spring_u = NodeMat::Zero(m.n, 3);
  for (int i = 0; i < m.n; ++i) {
    if (m.rest.positions(i, 0) > L / 2 - 1e-12) in.force(i, 0) = -0.05;  // the +x face pushed
    if (m.rest.positions(i, 1) > L / 2 - 1e-12) in.spring_k(i, 1) = 40.0 + i;  // the +y face held
  }
  for (int k = 1; k <= 3; ++k) {
    scenario::press_top(m, L, -0.004 * k, in);
    step(m, in, s);
  }
  ASSERT_FALSE(s.failed);
  const StepWorkspace& w = *s.work;
  ASSERT_TRUE(w.last_springs_any);
  ASSERT_GT(w.force.cwiseAbs().maxCoeff(), 0.0);
  std::vector<double> rows(result_rows_size(m.n));
  int cases = 0;
  for (const bool stress : {true, false})
    for (const double bc : {2000.0, 0.0})
      for (const bool loads : {true, false})
        for (const bool springs : {true, false}) {
          if (!stress && bc == 0.0) continue;  // (the same pass as with the capsule term)
          SCOPED_TRACE(::testing::Message() << "stress " << stress << " B_c " << bc << " loads " << loads
                                            << " springs " << springs);
          m.compute_stress = stress;
          m.connectivity_modulus = bc;
          const StepResultsInput input{w.K, w.mask, loads ? &w.force : nullptr, springs ? &w.last_springs : nullptr,
                                       w.area_norms, w.rhs, w.a_free};
          NodeMat Ku;
          s.strain.setConstant(7.0);
          s.stress.setConstant(7.0);
          const ResidualSums want = plain_results(m, input, s, Ku);
          const NodeMat reaction = s.reaction, strain = s.strain, stress_want = s.stress;
          const Vec pressure = s.reaction_pressure;
          ASSERT_GT(reaction.cwiseAbs().maxCoeff(), 0.0);
          s.reaction.setConstant(7.0);
          s.reaction_pressure.setConstant(7.0);
          s.strain.setConstant(7.0);
          s.stress.setConstant(7.0);
          const ResidualSums got = compute_step_results(m, input, s, rows.data());
          // Round-off of sums over a node's neighbours, in another order than the scatter's.
          const double ku_scale = Ku.norm();
          EXPECT_TRUE(close(s.reaction, reaction, 1e-12));
          EXPECT_LE((s.reaction_pressure - pressure).cwiseAbs().maxCoeff(), 1e-12 * pressure.cwiseAbs().maxCoeff());
          for (int d = 0; d < 3; ++d) {
            EXPECT_LE(std::abs(std::sqrt(got.free2[d]) - std::sqrt(want.free2[d])), 1e-13 * ku_scale) << "axis " << d;
            EXPECT_NEAR(got.rhs2[d], want.rhs2[d], 1e-14 * want.rhs2[d]) << "axis " << d;
            EXPECT_NEAR(got.volume_row[d], want.volume_row[d], 1e-14 * w.a_free.norm() * s.u.norm()) << "axis " << d;
          }
          if (stress) {
            EXPECT_TRUE(close(s.strain, strain, 1e-13));
            EXPECT_TRUE(close(s.stress, stress_want, 1e-12));
            for (const int i : m.infinite_nodes)
              for (int d = 0; d < 3; ++d) {
                if (m.infinite(i, d)) {
                  EXPECT_EQ(s.strain(i, d), 0.0);
                }
              }
          } else {
            EXPECT_EQ(s.strain.cwiseAbs().minCoeff(), 7.0) << "no stress: strain untouched";
            EXPECT_EQ(s.stress.cwiseAbs().minCoeff(), 7.0) << "no stress: stress untouched";
          }
          ++cases;
        }
  EXPECT_EQ(cases, 12);
}

// The same numbers run after run, and from a scratch of any content.
TEST(StepResults, Deterministic) {
  const double L = 0.1;
  const TissueModel m = scenario::build(scenario::cube_on_table(L, 4));
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  scenario::press_top(m, L, -0.006, in);
  step(m, in, s);
  ASSERT_FALSE(s.failed);
  const StepWorkspace& w = *s.work;
  const StepResultsInput input{w.K, w.mask, nullptr, nullptr, w.area_norms, w.rhs, w.a_free};
  std::vector<double> rows(result_rows_size(m.n));
  const ResidualSums first = compute_step_results(m, input, s, rows.data());
  const NodeMat reaction = s.reaction, stress = s.stress;
  std::fill(rows.begin(), rows.end(), std::nan(""));
  const ResidualSums again = compute_step_results(m, input, s, rows.data());
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(first.free2[d], again.free2[d]);
    EXPECT_EQ(first.rhs2[d], again.rhs2[d]);
    EXPECT_EQ(first.volume_row[d], again.volume_row[d]);
  }
  EXPECT_EQ(reaction, s.reaction);
  EXPECT_EQ(stress, s.stress);
}

}  // namespace
}  // namespace vdm
