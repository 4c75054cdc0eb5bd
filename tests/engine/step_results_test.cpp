// The step's results pass (one gather over the neighbour lists) against the plain kernels it
// replaced: K u by the edge-list product, the residual and reaction loop written out entry by
// entry, and compute_strain_stress().
#include <gtest/gtest.h>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "engine/node_ordering.hpp"
#include "engine/shapes.hpp"
#include "engine/membrane_strain.hpp"
#include "engine/step_results.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stiffness.hpp"
#include "engine/stress.hpp"
#include "support/scenarios.hpp"

namespace vdm {
namespace {

// What the pass must give, the plain way: reactions and contact pressures written into `s`
// (compute_strain_stress reads the reactions), the sums returned.
// `a_free`: the step's area vectors with zeros on the constrained entries (its volume row),
// which the pass takes from the area vectors and the mask.
ResidualSums plain_results(const TissueModel& m, const StepResultsInput& in, const NodeMat& a_free, SimState& s,
                           NodeMat& Ku) {
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
      sums.volume_row[d] += a_free(i, d) * s.u(i, d);
    }
    const double an = in.area_norms[i];
    s.reaction_pressure[i] = any && an > 0 ? s.reaction.row(i).norm() / an : 0.0;
  }
  if (m.compute_stress) {
    std::vector<double> scratch(4 * size_t(m.n));
    compute_strain_stress(m, s, scratch.data());
  }
  return sums;
}

// The pass's arithmetic written out node by node, entry by entry: each neighbour sum from +0
// in list order, the sums of even and of odd nodes apart and then added, 1 / V_i once per
// node. The pass must give these bits exactly (its unrolled gather of two degree-6 nodes,
// its loop for others, its pairs of nodes are only another schedule of the same operations).
ResidualSums list_order_results(const TissueModel& m, const StepResultsInput& in, const NodeMat& a_free, SimState& s) {
  const NeighbourLists& l = m.neighbours;
  double free2[3][2] = {}, rhs2[3][2] = {}, volume_row[3][2] = {};
  for (int i = 0; i < m.n; ++i) {
    const int lane = i % 2;
    double wu[3] = {0, 0, 0}, dv_sum[3] = {0, 0, 0}, r[3];
    for (int k = l.begin[size_t(i)]; k < l.begin[size_t(i) + 1]; ++k) {
      const NeighbourLists::Entry e = l.entries[size_t(k)];
      const double w = in.K.weight[e.edge];
      for (int d = 0; d < 3; ++d) {
        wu[d] += w * s.u(e.node, d);
        dv_sum[d] += s.area_vectors(e.node, d) * s.u(e.node, d);
      }
    }
    bool any = false;
    for (int d = 0; d < 3; ++d) {
      double base = in.K.diagonal(i, d) * s.u(i, d) - wu[d] - s.pressure * s.area_vectors(i, d);
      if (in.force) base -= (*in.force)(i, d);
      double free_r = base;
      if (in.springs) free_r += (*in.springs)(i, d) * s.u(i, d);
      const bool held = in.mask(i, d) != 0;
      any = any || held;
      r[d] = held ? base : 0.0;
      s.reaction(i, d) = r[d];
      if (!held) free2[d][lane] += free_r * free_r;
      rhs2[d][lane] += in.rhs(i, d) * in.rhs(i, d);
      volume_row[d][lane] += a_free(i, d) * s.u(i, d);
    }
    const double an = in.area_norms[i];
    s.reaction_pressure[i] = any && an > 0 ? std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) / an : 0.0;
    if (m.compute_stress) {
      const double inv_v = 1.0 / s.node_volumes[i];
      const double degree = double(l.begin[size_t(i) + 1] - l.begin[size_t(i)]);
      for (int d = 0; d < 3; ++d) {
        const double dv = s.area_vectors(i, d) * s.u(i, d);
        const double eps = dv * inv_v;
        s.strain(i, d) = eps;
        // The paper's volumic tension (a membrane's stress is added from its strain below).
        const double capsule = m.membrane_capsule() ? 0.0 : m.connectivity_modulus * (degree * dv - dv_sum[d]) * inv_v;
        s.stress(i, d) = m.bulk(i, d) * eps + capsule;
      }
    }
  }
  if (m.compute_stress)
    for (const int i : m.infinite_nodes) {
      const double tiny = 1e-9 * s.area_vectors.row(i).norm();
      for (int d = 0; d < 3; ++d) {
        if (!m.infinite(i, d)) continue;
        s.strain(i, d) = 0.0;
        const double a = s.area_vectors(i, d);
        s.stress(i, d) += std::abs(a) > tiny ? -s.reaction(i, d) / a : 0.0;
      }
    }
  if (m.compute_stress && m.membrane_capsule()) {  // (its own test: StrainStress.MembraneStress*)
    std::vector<double> scratch(4 * size_t(m.n));
    add_membrane_stress(m, s, scratch.data());
  }
  ResidualSums sums;
  for (int d = 0; d < 3; ++d) {
    sums.free2[d] = free2[d][0] + free2[d][1];
    sums.rhs2[d] = rhs2[d][0] + rhs2[d][1];
    sums.volume_row[d] = volume_row[d][0] + volume_row[d][1];
  }
  return sums;
}

// Entries whose bits differ (a NaN equals a NaN of the same bits; -0 differs from +0).
template <typename Mat>
int differing_bits(const Mat& a, const Mat& b) {
  int count = 0;
  for (Eigen::Index k = 0; k < a.size(); ++k) {
    std::uint64_t x, y;
    std::memcpy(&x, a.data() + k, sizeof x);
    std::memcpy(&y, b.data() + k, sizeof y);
    count += x != y;
  }
  return count;
}
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

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
  def.capsule = CapsuleForm::paper;  // B_c varies below (the membrane's pass: StepResultsBall)
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
                                       w.area_norms, w.rhs};
          NodeMat Ku;
          s.strain.setConstant(7.0);
          s.stress.setConstant(7.0);
          const ResidualSums want = plain_results(m, input, w.a_free, s, Ku);
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

// An icosphere of `level` with one more node at the centroid of triangle 0 (an odd count)
// when `odd`, renumbered in locality order when `local`.
SurfaceMesh ball_mesh(double R, int level, bool odd, bool local) {
  SurfaceMesh mesh = make_icosphere(R, level);
  if (odd) {
    const int n = mesh.node_count(), t = mesh.triangle_count();
    const int a = mesh.triangles(0, 0), b = mesh.triangles(0, 1), c = mesh.triangles(0, 2);
    mesh.positions.conservativeResize(n + 1, 3);
    const Vec3 centre = (mesh.positions.row(a) + mesh.positions.row(b) + mesh.positions.row(c)).transpose() / 3.0;
    mesh.positions.row(n) = (R * centre.normalized()).transpose();
    mesh.triangles.conservativeResize(t + 2, 3);
    mesh.triangles.row(0) << a, b, n;
    mesh.triangles.row(t) << b, c, n;
    mesh.triangles.row(t + 1) << c, a, n;
  }
  if (local) renumber_for_locality(mesh);
  return mesh;
}

// The same bits as the node-by-node loop in list order, in every case of the pass, on a ball
// (an icosphere: degree 6 but at 12 nodes) pressed at its top, with pairs of degree-6 nodes
// (the unrolled gather) and pairs with a degree-5 node (the loop); in the icosphere's own
// order (neighbours far apart in index: the planes of all nodes) and in locality order (the
// ring of planes), with an even and an odd node count (the last node alone).
class StepResultsBall : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(StepResultsBall, SameBitsAsTheNodeByNodeLoop) {
  const auto [odd, local] = GetParam();
  const double R = 0.05;
  TissueDef def = default_tissue(ball_mesh(R, 3, odd, local));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.8 * R) def.fixed.row(i).setOnes();
  def.bulk_modulus = NodeMat::Constant(n, 3, 20000.0);
  for (int i = 0; i < n; i += 5) def.bulk_modulus(i, 2) = std::numeric_limits<double>::infinity();
  TissueModel m = scenario::build(def);
  ASSERT_EQ(m.n % 2, odd ? 1 : 0);
  // In locality order the pass packs the nodes into a ring a few neighbourhoods long, which
  // wraps round twice or more; in the icosphere's own order (neighbours up to n apart) into
  // planes of all n nodes, before the gather.
  const std::ptrdiff_t ring = result_ring_nodes(m.neighbours.reach, m.n);
  if (local) EXPECT_LE(2 * ring, m.n);
  else EXPECT_EQ(ring, m.n);
  int fixed_pairs = 0, other_pairs = 0;
  for (int i = 0; i + 1 < m.n; i += 2) {
    const int* b = m.neighbours.begin.data() + i;
    (b[1] - b[0] == 6 && b[2] - b[1] == 6 ? fixed_pairs : other_pairs) += 1;
  }
  EXPECT_GT(fixed_pairs, 0);
  EXPECT_GT(other_pairs, 0);
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  in.spring_k = NodeMat::Zero(m.n, 3);
  in.spring_u = NodeMat::Zero(m.n, 3);
  for (int i = 0; i < m.n; ++i) {
    if (m.rest.positions(i, 0) > 0.6 * R) in.force(i, 0) = -0.05;        // pushed along -x
    if (m.rest.positions(i, 1) > 0.6 * R) in.spring_k(i, 1) = 40.0 + i;  // held along y
  }
  for (int k = 1; k <= 2; ++k) {
    for (int i = 0; i < m.n; ++i)
      if (m.rest.positions(i, 2) > 0.8 * R) {  // the top pressed down
        in.prescribed(i, 2) = 1;
        in.prescribed_u(i, 2) = -0.002 * k;
      }
    step(m, in, s);
  }
  ASSERT_FALSE(s.failed);
  const StepWorkspace& w = *s.work;
  ASSERT_TRUE(w.last_springs_any);
  std::vector<double> rows(result_rows_size(m.n));
  for (const bool stress : {true, false})
    for (const bool loads : {true, false})
      for (const bool springs : {true, false}) {
        SCOPED_TRACE(::testing::Message() << "stress " << stress << " loads " << loads << " springs " << springs);
        m.compute_stress = stress;
        m.connectivity_modulus = 2000.0;
        const StepResultsInput input{w.K, w.mask, loads ? &w.force : nullptr, springs ? &w.last_springs : nullptr,
                                     w.area_norms, w.rhs};
        s.strain.setConstant(7.0);
        s.stress.setConstant(7.0);
        const ResidualSums want = list_order_results(m, input, w.a_free, s);
        const NodeMat reaction = s.reaction, strain = s.strain, stress_want = s.stress;
        const Vec pressure = s.reaction_pressure;
        ASSERT_GT(reaction.cwiseAbs().maxCoeff(), 0.0);
        s.reaction.setConstant(7.0);
        s.reaction_pressure.setConstant(7.0);
        s.strain.setConstant(7.0);
        s.stress.setConstant(7.0);
        std::fill(rows.begin(), rows.end(), std::nan(""));
        const ResidualSums got = compute_step_results(m, input, s, rows.data());
        EXPECT_EQ(differing_bits(s.reaction, reaction), 0);
        EXPECT_EQ(differing_bits(s.reaction_pressure, pressure), 0);
        EXPECT_EQ(differing_bits(s.strain, strain), 0);
        EXPECT_EQ(differing_bits(s.stress, stress_want), 0);
        for (int d = 0; d < 3; ++d) {
          EXPECT_TRUE(same_bits(got.free2[d], want.free2[d])) << "axis " << d;
          EXPECT_TRUE(same_bits(got.rhs2[d], want.rhs2[d])) << "axis " << d;
          EXPECT_TRUE(same_bits(got.volume_row[d], want.volume_row[d])) << "axis " << d;
        }
      }
}

INSTANTIATE_TEST_SUITE_P(OrdersAndCounts, StepResultsBall,
                         ::testing::Combine(::testing::Bool(), ::testing::Bool()),
                         [](const ::testing::TestParamInfo<std::tuple<bool, bool>>& info) {
                           return std::string(std::get<0>(info.param) ? "Odd" : "Even") +
                                  (std::get<1>(info.param) ? "LocalityOrder" : "OwnOrder");
                         });

// A step whose results are deferred (StepResults::reactions or none, then
// finish_step_results) leaves the state of a step with StepResults::all, bit for bit: with
// loads, springs, prescribed and held entries, stress on. With `reactions` the reactions at
// the entries the input prescribes are those values already before finish_step_results()
// (a held node prescribed too included); after a rewind_step() there is nothing to finish
// (the results stay as they were).
TEST(StepResults, DeferredResultsAreThoseOfAWholeStep) {
  const double L = 0.1;
  TissueDef def = scenario::cube_on_table(L, 4);
  def.solver.tolerance = 1e-8;
  const TissueModel m = scenario::build(def);
  ASSERT_TRUE(m.compute_stress);
  for (const StepResults mode : {StepResults::reactions, StepResults::none}) {
    SCOPED_TRACE(mode == StepResults::reactions ? "reactions" : "none");
    SimState whole = make_sim_state(m), deferred = make_sim_state(m);
    StepInput in = make_step_input(m);
    in.spring_k = NodeMat::Zero(m.n, 3);
    in.spring_u = NodeMat::Zero(m.n, 3);
    for (int i = 0; i < m.n; ++i) {
      if (m.rest.positions(i, 0) > L / 2 - 1e-12) in.force(i, 0) = -0.05;
      if (m.rest.positions(i, 1) > L / 2 - 1e-12) in.spring_k(i, 1) = 40.0 + i;
      if (m.rest.positions(i, 2) < -L / 2 + 1e-12 && i % 2 == 0) in.prescribed(i, 0) = 1;  // held (fixed) too
    }
    for (int k = 1; k <= 3; ++k) {
      scenario::press_top(m, L, -0.004 * k, in);
      // A tentative step first, undone, as the contact's active set does; the same for both.
      step(m, in, whole);
      rewind_step(m, whole);
      step(m, in, whole);
      step(m, in, deferred, mode);
      rewind_step(m, deferred);
      deferred.stress.setConstant(7.0);
      finish_step_results(m, deferred);  // nothing pending: no change
      EXPECT_EQ(deferred.stress.minCoeff(), 7.0);
      EXPECT_EQ(deferred.stress.maxCoeff(), 7.0);
      step(m, in, deferred, mode);
      ASSERT_FALSE(whole.failed);
      ASSERT_FALSE(deferred.failed);
      if (mode == StepResults::reactions) {
        int constrained = 0;
        for (int d = 0; d < 3; ++d)
          for (int i = 0; i < m.n; ++i) {
            if (!in.prescribed(i, d)) continue;
            ++constrained;
            EXPECT_TRUE(same_bits(deferred.reaction(i, d), whole.reaction(i, d))) << "node " << i << " axis " << d;
          }
        EXPECT_GT(constrained, 0);
      }
      finish_step_results(m, deferred);
      EXPECT_TRUE(same_bits(deferred.stats.residual, whole.stats.residual));
      for (const auto& [got, want] : {std::pair{&deferred.reaction, &whole.reaction}, {&deferred.strain, &whole.strain},
                                      {&deferred.stress, &whole.stress}, {&deferred.u, &whole.u}})
        for (Eigen::Index k = 0; k < got->size(); ++k) ASSERT_TRUE(same_bits(got->data()[k], want->data()[k])) << k;
      for (int i = 0; i < m.n; ++i)
        ASSERT_TRUE(same_bits(deferred.reaction_pressure[i], whole.reaction_pressure[i])) << i;
      EXPECT_GT(whole.reaction.cwiseAbs().maxCoeff(), 0.0);
      EXPECT_GT(whole.stress.cwiseAbs().maxCoeff(), 0.0);
    }
  }
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
  const StepResultsInput input{w.K, w.mask, nullptr, nullptr, w.area_norms, w.rhs};
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
