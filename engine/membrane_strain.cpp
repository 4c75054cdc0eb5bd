#include "engine/membrane_strain.hpp"

#include <algorithm>
#include <cmath>

namespace vdm {

std::vector<double> membrane_frames(const SurfaceMesh& rest) {
  std::vector<double> out(size_t(rest.triangle_count()) * kMembraneFrameSize, 0.0);
  for (int t = 0; t < rest.triangle_count(); ++t) {
    const Vec3 a = rest.positions.row(rest.triangles(t, 0)), b = rest.positions.row(rest.triangles(t, 1)),
               c = rest.positions.row(rest.triangles(t, 2));
    const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
    double* f = out.data() + size_t(t) * kMembraneFrameSize;
    const double area2 = n.norm();
    if (!(area2 > 0.0) || !(ab.norm() > 0.0)) continue;  // degenerate: no strain (the mesh check refuses these)
    const Vec3 e1 = ab.normalized(), e2 = n.cross(ab).normalized();
    // D in the basis: columns (ab.e1, ab.e2) = (|ab|, 0) and (ac.e1, ac.e2).
    const double d00 = ab.dot(e1), d01 = ac.dot(e1), d10 = 0.0, d11 = ac.dot(e2);
    const double det = d00 * d11 - d01 * d10;
    for (int k = 0; k < 3; ++k) {
      f[k] = e1[k];
      f[3 + k] = e2[k];
    }
    f[6] = d11 / det;
    f[7] = -d01 / det;
    f[8] = -d10 / det;
    f[9] = d00 / det;
    f[10] = 0.5 * area2;
  }
  return out;
}

namespace {

// The area-weighted sums of E_dd (acc, 3 N) and the areas (weight, N) at the displacement u.
void accumulate_strain(const TissueModel& m, const NodeMat& u, double* acc, double* weight) {
  std::fill(acc, acc + 3 * size_t(m.n), 0.0);
  std::fill(weight, weight + size_t(m.n), 0.0);
  const TriMat& tris = m.rest.triangles;
  for (int t = 0; t < tris.rows(); ++t) {
    const double* f = m.membrane_frames.data() + size_t(t) * kMembraneFrameSize;
    const double area = f[10];
    if (area == 0.0) continue;
    const int a = tris(t, 0), b = tris(t, 1), c = tris(t, 2);
    const Vec3 ab = (u.row(b) - u.row(a)).transpose(), ac = (u.row(c) - u.row(a)).transpose();
    // The displacement's gradient in the rest plane, H = [u_ab u_ac] D⁻¹ (3 x 2), so F = P + H
    // with P = [e1 e2], and E = ½ (Pᵀ H + Hᵀ P + Hᵀ H): exactly zero at rest, no cancellation.
    const Vec3 H0 = ab * f[6] + ac * f[8], H1 = ab * f[7] + ac * f[9];
    const Vec3 e1(f[0], f[1], f[2]), e2(f[3], f[4], f[5]);
    const double E00 = e1.dot(H0) + 0.5 * H0.dot(H0), E11 = e2.dot(H1) + 0.5 * H1.dot(H1);
    const double E01 = 0.5 * (e1.dot(H1) + e2.dot(H0) + H0.dot(H1));
    // E3_dd = Σ_pq P_dp E_pq P_dq with P = [e1 e2].
    for (int d = 0; d < 3; ++d) {
      const double p0 = f[d], p1 = f[3 + d];
      const double e = p0 * p0 * E00 + 2.0 * p0 * p1 * E01 + p1 * p1 * E11;
      for (const int i : {a, b, c}) acc[3 * size_t(i) + size_t(d)] += area * e;
    }
    for (const int i : {a, b, c}) weight[i] += area;
  }
}

}  // namespace

void membrane_axis_strain(const TissueModel& m, const NodeMat& u, NodeMat& strain_dd, double* scratch) {
  double* acc = scratch;
  double* weight = scratch + 3 * size_t(m.n);
  accumulate_strain(m, u, acc, weight);
  for (int i = 0; i < m.n; ++i)
    for (int d = 0; d < 3; ++d) strain_dd(i, d) = weight[i] > 0.0 ? acc[3 * size_t(i) + size_t(d)] / weight[i] : 0.0;
}

void add_membrane_stress(const TissueModel& m, SimState& s, double* scratch) {
  double* acc = scratch;
  double* weight = scratch + 3 * size_t(m.n);
  accumulate_strain(m, s.u, acc, weight);
  const double bc = m.connectivity_modulus;
  for (int i = 0; i < m.n; ++i)
    if (weight[i] > 0.0)
      for (int d = 0; d < 3; ++d) s.stress(i, d) += bc * acc[3 * size_t(i) + size_t(d)] / weight[i];
}

}  // namespace vdm
