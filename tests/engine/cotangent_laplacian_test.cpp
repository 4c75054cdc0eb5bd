// The membrane capsule's Laplacian: cotangent weights on the intrinsic Delaunay triangulation.
// Checked against what a discretisation of the Dirichlet energy must do: reproduce linear
// functions on a flat patch, give the mean-curvature normal on a sphere (converging under
// refinement), keep every weight >= 0 where plain cotangents go negative.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "engine/cotangent_laplacian.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"

namespace vdm {
namespace {

// (L X)_i = sum_j w_ij (X_i - X_j) for every node.
NodeMat apply(const CotangentWeights& c, const NodeMat& x) {
  NodeMat out = NodeMat::Zero(x.rows(), 3);
  for (size_t e = 0; e < c.edges.size(); ++e) {
    const int i = c.edges[e][0], j = c.edges[e][1];
    const Vec3 d = c.weights[e] * (x.row(i) - x.row(j)).transpose();
    out.row(i) += d.transpose();
    out.row(j) -= d.transpose();
  }
  return out;
}

// A box with its nodes moved at random along its faces (flat faces stay flat; the fan
// triangles turn obtuse here and there).
SurfaceMesh jittered_box(double amount, unsigned seed) {
  SurfaceMesh m = make_box(Vec3(1.0, 1.0, 1.0), 8, 8, 8);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-amount, amount);
  for (int i = 0; i < m.node_count(); ++i)
    for (int d = 0; d < 3; ++d) {
      // only along axes in which the node is strictly inside its face (edges and corners stay)
      bool on_faces_of_d = std::abs(std::abs(m.positions(i, d)) - 0.5) < 1e-12;
      int faces = 0;
      for (int e = 0; e < 3; ++e) faces += std::abs(std::abs(m.positions(i, e)) - 0.5) < 1e-12;
      if (!on_faces_of_d && faces == 1) m.positions(i, d) += uni(rng);
    }
  return m;
}

TEST(CotangentLaplacian, ReproducesLinearFunctionsOnFlatFaces) {
  const SurfaceMesh m = jittered_box(0.015, 3);
  for (const bool delaunay : {false, true}) {
    const CotangentWeights c = cotangent_weights(m.positions, m.triangles, delaunay);
    const NodeMat lx = apply(c, m.positions);
    int interior = 0;
    for (int i = 0; i < m.node_count(); ++i) {
      int faces = 0;
      for (int e = 0; e < 3; ++e) faces += std::abs(std::abs(m.positions(i, e)) - 0.5) < 1e-12;
      if (faces != 1) continue;  // on an edge or corner of the box: curved there
      // the neighbours are on the same flat face only if none is on another: skip rims
      bool rim = false;
      for (size_t e = 0; e < c.edges.size(); ++e)
        if (c.edges[e][0] == i || c.edges[e][1] == i) {
          const int j = c.edges[e][0] == i ? c.edges[e][1] : c.edges[e][0];
          int fj = 0;
          for (int k = 0; k < 3; ++k) fj += std::abs(std::abs(m.positions(j, k)) - 0.5) < 1e-12;
          if (fj != 1) rim = true;
        }
      if (rim) continue;
      ++interior;
      EXPECT_LT(lx.row(i).norm(), 1e-12) << "node " << i << (delaunay ? " (Delaunay)" : " (plain)");
    }
    EXPECT_GT(interior, 100);
  }
}

TEST(CotangentLaplacian, DelaunayFlipsLeaveNoNegativeWeight) {
  const SurfaceMesh m = jittered_box(0.015, 7);
  const CotangentWeights plain = cotangent_weights(m.positions, m.triangles, false);
  const CotangentWeights idt = cotangent_weights(m.positions, m.triangles, true);
  int negative = 0;
  for (const double w : plain.weights) negative += w < -1e-12;
  ASSERT_GT(negative, 0) << "the jitter must make some plain weight negative for this test to mean anything";
  EXPECT_GT(idt.flips, 0);
  for (const double w : idt.weights) EXPECT_GE(w, -1e-12);
  // The same energy of a linear field: on the flat faces both discretise it exactly; an edge
  // flipped across one of the box's creases spans two faces, where the field restricted to
  // the surface is not linear, so the two differ by a little there.
  Vec f(m.node_count());
  for (int i = 0; i < m.node_count(); ++i) f[i] = 0.3 * m.positions(i, 0) - 0.7 * m.positions(i, 1) + m.positions(i, 2);
  auto energy = [&](const CotangentWeights& c) {
    double e = 0;
    for (size_t k = 0; k < c.edges.size(); ++k) {
      const double d = f[c.edges[k][0]] - f[c.edges[k][1]];
      e += 0.5 * c.weights[k] * d * d;
    }
    return e;
  };
  EXPECT_NEAR(energy(idt), energy(plain), 0.01 * energy(plain));
}

TEST(CotangentLaplacian, MeanCurvatureOfASphereConverges) {
  // |(L X)_i| / |A_i| = 2 H = 2 / R on a sphere. The cotangent Laplacian converges in the
  // mean (weakly), not node by node on irregular meshes: the area-weighted mean error falls
  // as the icosphere is refined.
  const double R = 0.05;
  double last_error = 1e9;
  for (int level = 2; level <= 5; ++level) {
    const SurfaceMesh m = make_icosphere(R, level);
    const CotangentWeights c = cotangent_weights(m.positions, m.triangles, false);
    const NodeMat lx = apply(c, m.positions);
    NodeMat a(m.node_count(), 3);
    distributed_area_vectors(m.positions, m.triangles, a);
    double error = 0, area = 0;
    for (int i = 0; i < m.node_count(); ++i) {
      const double h2 = lx.row(i).norm() / a.row(i).norm();
      error += a.row(i).norm() * std::abs(h2 * R / 2.0 - 1.0);
      area += a.row(i).norm();
      EXPECT_GT(lx.row(i).dot(a.row(i)), 0.0) << "L X points outward like the normal";
    }
    error /= area;
    std::printf("icosphere level %d: mean |2H R / 2 - 1| = %.4f\n", level, error);
    EXPECT_LT(error, 0.05) << "level " << level;
    if (level >= 3) {
      EXPECT_LT(error, last_error) << "level " << level;
    }
    last_error = error;
  }
}

}  // namespace
}  // namespace vdm
