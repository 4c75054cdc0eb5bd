// The capsule's bending term (docs/model.md, "Bending"): its pair weights are D C M⁻¹ C, its
// energy converges to ½ D ∫ |Δ_S u|² dA under refinement, and a tube of skin that resists
// bending alone bends like an Euler-Bernoulli beam.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "engine/capsule_bending.hpp"
#include "engine/cotangent_laplacian.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/sim_state.hpp"
#include "engine/tissue_model.hpp"

namespace vdm {
namespace {

// Σ_pairs w (u_i − u_j)² with w the pairs' bending weights, or their cotangent weights
// (`cot`): twice the energy of one component u over the pairs.
double pair_energy2(const CapsulePairs& p, const Vec& u, bool cot = false) {
  double e = 0;
  for (size_t k = 0; k < p.edges.size(); ++k) {
    const double d = u[p.edges[k][0]] - u[p.edges[k][1]];
    e += (cot ? p.cot[k] : p.bending[k]) * d * d;
  }
  return e;
}

// The barycentric rest areas M_i = Σ_{t∋i} |t| / 3.
Vec barycentric_areas(const SurfaceMesh& mesh) {
  Vec M = Vec::Zero(mesh.node_count());
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3 a = mesh.positions.row(mesh.triangles(t, 0)), b = mesh.positions.row(mesh.triangles(t, 1)),
               c = mesh.positions.row(mesh.triangles(t, 2));
    const double third = 0.5 * (b - a).cross(c - a).norm() / 3.0;
    for (int k = 0; k < 3; ++k) M[mesh.triangles(t, k)] += third;
  }
  return M;
}

// The bending term's pairs on `mesh` with modulus D.
CapsulePairs bending_pairs(const SurfaceMesh& mesh, double D) {
  const CotangentWeights cot = cotangent_weights(mesh.positions, mesh.triangles, false);
  return capsule_bending_pairs(cot.edges, cot.weights, barycentric_areas(mesh), D);
}

TEST(CapsuleBending, PairWeightsAreTheMatrixDCMinvC) {
  // On an irregular closed surface and a random field, the pairs' energy is D Σ |(C u)_i|² / M_i
  // computed from the cotangent weights directly; the cotangent weights pass through.
  SurfaceMesh mesh = make_icosphere(0.05, 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002), value(-1.0, 1.0);
  for (int i = 0; i < mesh.node_count(); ++i)
    for (int d = 0; d < 3; ++d) mesh.positions(i, d) += jitter(rng);
  const CotangentWeights cot = cotangent_weights(mesh.positions, mesh.triangles, false);
  const double D = 2e-3;
  const Vec M = barycentric_areas(mesh);
  const CapsulePairs p = capsule_bending_pairs(cot.edges, cot.weights, M, D);
  EXPECT_GT(p.edges.size(), 2 * cot.edges.size());  // the two-ring pairs joined the edges
  Vec u(mesh.node_count());
  for (int i = 0; i < u.size(); ++i) u[i] = value(rng);
  Vec cu = Vec::Zero(u.size());
  double cot2 = 0;
  for (size_t e = 0; e < cot.edges.size(); ++e) {
    const int i = cot.edges[e][0], j = cot.edges[e][1];
    const double d = u[i] - u[j];
    cu[i] += cot.weights[e] * d;
    cu[j] -= cot.weights[e] * d;
    cot2 += cot.weights[e] * d * d;
  }
  double bending2 = 0;
  for (int i = 0; i < u.size(); ++i) bending2 += D * cu[i] * cu[i] / M[i];
  EXPECT_NEAR(pair_energy2(p, u, true), cot2, 1e-12 * cot2);
  EXPECT_NEAR(pair_energy2(p, u), bending2, 1e-10 * bending2);
  // A translation costs nothing: the weights form a Laplacian (rows summing to zero).
  EXPECT_NEAR(pair_energy2(p, Vec::Constant(u.size(), 0.7)), 0.0, 1e-14);
}

TEST(CapsuleBending, EnergyConvergesToTheContinuumOnASphere) {
  // u = z on a sphere of radius R: Δ_S z = −2 z / R², so ½ D ∫ (Δ_S u)² dA = ½ D (16 π / 3),
  // whatever R. The discrete energy converges to it as the icosphere is refined.
  const double D = 1.0, R = 0.05, exact = 0.5 * D * 16.0 * M_PI / 3.0;
  double previous_error = 1e300;
  for (int level = 2; level <= 5; ++level) {
    const SurfaceMesh mesh = make_icosphere(R, level);
    const CapsulePairs p = bending_pairs(mesh, D);
    const Vec u = mesh.positions.col(2);
    const double energy = 0.5 * pair_energy2(p, u), error = std::abs(energy - exact) / exact;
    std::printf("icosphere level %d (%5d nodes): bending energy %.5f J, continuum %.5f J, %.2f %% off\n", level,
                mesh.node_count(), energy, exact, 100 * error);
    EXPECT_LT(error, previous_error) << "level " << level;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.02);
}

// A square tube (the surface of a 2 x 10 x 2 cm beam along y), the y = 0 end face held and
// the y = L end face moved sideways by delta on all three axes (no end rotation), with the
// skin resisting bending only (membrane and bulk nearly off: T L^2 / D = 5e-5): the top face's
// centre line at y = L/4, L/2, 3L/4, as a share of delta.
std::array<double, 3> guided_tube(double D, SolverMethod method = SolverMethod::direct, int* fallbacks = nullptr) {
  const double L = 0.1, w = 0.02, delta = 1e-3;
  TissueDef def = default_tissue(make_box(Vec3(w, L, w), 4, 20, 4, Vec3(0, L / 2, 0)));
  def.bulk = 1e-6;
  def.connectivity_modulus = 1e-3;
  def.bending_modulus = D;
  def.solver.method = method;
  def.solver.tolerance = method == SolverMethod::direct ? 1e-12 : 1e-8;
  def.compute_stress = false;
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 1) < 1e-12) def.fixed.row(i).setOnes();
  TissueModel m;
  std::string error;
  if (!build_tissue_model(def, m, error)) {
    ADD_FAILURE() << error;
    return {};
  }
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  for (int i = 0; i < n; ++i)
    if (m.rest.positions(i, 1) > L - 1e-12) {
      in.prescribed.row(i).setOnes();
      in.prescribed_u.row(i) << delta, 0, 0;
    }
  step(m, in, s);
  if (fallbacks) *fallbacks = s.stats.fallbacks;
  EXPECT_FALSE(s.failed) << s.failure;
  EXPECT_LT(std::abs(s.volume_rel_error), 1e-9);
  std::array<double, 3> share{};
  for (int k = 1; k <= 3; ++k) share[size_t(k - 1)] = s.u(nearest_node(m.rest.positions, Vec3(0, k * L / 4, w / 2)), 0) / delta;
  return share;
}

TEST(CapsuleBending, TubeOfBendingSkinTakesTheEulerBernoulliProfile) {
  // Euler-Bernoulli's guided cantilever: w(s) = delta (3 s² − 2 s³), s = y / L.
  const double expected[3] = {3.0 / 16 - 2.0 / 64, 0.5, 27.0 / 16 - 54.0 / 64};
  const std::array<double, 3> bent = guided_tube(1e-3);
  std::printf("bending skin: %.4f %.4f %.4f of delta (Euler-Bernoulli %.4f %.4f %.4f)\n", bent[0], bent[1], bent[2],
              expected[0], expected[1], expected[2]);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(bent[size_t(k)], expected[k], 0.015) << "point " << k;
  // The default (structured PCG) solver takes the bending pairs (weights of either sign) too,
  // without falling back to the direct one (its incomplete factorisation moves the positive
  // pairs onto the diagonal: AxisIncompleteCholesky::factorize's `compensate`).
  int fallbacks = -1;
  const std::array<double, 3> structured = guided_tube(1e-3, SolverMethod::structured, &fallbacks);
  EXPECT_EQ(fallbacks, 0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(structured[size_t(k)], bent[size_t(k)], 1e-4) << "point " << k;
  // Without the bending term the same skin's membrane takes a straight line (harmonic along
  // the tube): the profile above is the bending term's.
  const std::array<double, 3> straight = guided_tube(0.0);
  std::printf("membrane skin: %.4f %.4f %.4f of delta\n", straight[0], straight[1], straight[2]);
  EXPECT_NEAR(straight[0], 0.25, 0.03);
  EXPECT_NEAR(straight[2], 0.75, 0.03);
}

TEST(CapsuleBending, TheModelRefusesItWithThePapersCapsule) {
  TissueDef def = default_tissue(make_icosphere(0.05, 2));
  def.bending_modulus = 1e-3;
  def.capsule = CapsuleForm::paper;
  TissueModel m;
  std::string error;
  EXPECT_FALSE(build_tissue_model(def, m, error));
  EXPECT_NE(error.find("bending_modulus"), std::string::npos) << error;
  def.capsule = CapsuleForm::membrane;
  def.bending_modulus = -1;
  EXPECT_FALSE(build_tissue_model(def, m, error));
  def.bending_modulus = 1e-3;
  ASSERT_TRUE(build_tissue_model(def, m, error)) << error;
  EXPECT_EQ(m.bending_modulus, 1e-3);
  EXPECT_EQ(m.bending_cot_weight.size(), m.capsule_weight.size());
}

}  // namespace
}  // namespace vdm
