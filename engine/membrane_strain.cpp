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

// The area-weighted sums of E_dd (acc, 3 N, node-major) and the areas (weight, N) at the
// displacement u. Written out on raw columns (no Eigen row views of the column-major u, no
// loops over 3): with the stress effect it runs every step, and so it takes about 190
// instructions per triangle where the loop form took 330.
void accumulate_strain(const TissueModel& m, const NodeMat& u, double* acc, double* weight) {
  std::fill(acc, acc + 3 * size_t(m.n), 0.0);
  std::fill(weight, weight + size_t(m.n), 0.0);
  const TriMat& tris = m.rest.triangles;
  const double* ux = u.col(0).data();
  const double* uy = u.col(1).data();
  const double* uz = u.col(2).data();
  const double* frames = m.membrane_frames.data();
  const int count = int(tris.rows());
  for (int t = 0; t < count; ++t) {
    const double* f = frames + size_t(t) * kMembraneFrameSize;
    const double area = f[10];
    if (area == 0.0) continue;
    const int a = tris(t, 0), b = tris(t, 1), c = tris(t, 2);
    const double ab[3] = {ux[b] - ux[a], uy[b] - uy[a], uz[b] - uz[a]};
    const double ac[3] = {ux[c] - ux[a], uy[c] - uy[a], uz[c] - uz[a]};
    // The displacement's gradient in the rest plane, H = [u_ab u_ac] D⁻¹ (3 x 2), so F = P + H
    // with P = [e1 e2], and E = ½ (Pᵀ H + Hᵀ P + Hᵀ H): exactly zero at rest, no cancellation.
    const double h0x = ab[0] * f[6] + ac[0] * f[8], h0y = ab[1] * f[6] + ac[1] * f[8], h0z = ab[2] * f[6] + ac[2] * f[8];
    const double h1x = ab[0] * f[7] + ac[0] * f[9], h1y = ab[1] * f[7] + ac[1] * f[9], h1z = ab[2] * f[7] + ac[2] * f[9];
    const double e1x = f[0], e1y = f[1], e1z = f[2], e2x = f[3], e2y = f[4], e2z = f[5];
    const double E00 = e1x * h0x + e1y * h0y + e1z * h0z + 0.5 * (h0x * h0x + h0y * h0y + h0z * h0z);
    const double E11 = e2x * h1x + e2y * h1y + e2z * h1z + 0.5 * (h1x * h1x + h1y * h1y + h1z * h1z);
    const double E01 = 0.5 * (e1x * h1x + e1y * h1y + e1z * h1z + e2x * h0x + e2y * h0y + e2z * h0z +
                              h0x * h1x + h0y * h1y + h0z * h1z);
    // E3_dd = Σ_pq P_dp E_pq P_dq with P = [e1 e2], times the area.
    const double a00 = area * E00, a01 = 2.0 * area * E01, a11 = area * E11;
    const double e[3] = {e1x * e1x * a00 + e1x * e2x * a01 + e2x * e2x * a11,
                         e1y * e1y * a00 + e1y * e2y * a01 + e2y * e2y * a11,
                         e1z * e1z * a00 + e1z * e2z * a01 + e2z * e2z * a11};
    double* na = acc + 3 * size_t(a);
    double* nb = acc + 3 * size_t(b);
    double* nc = acc + 3 * size_t(c);
    na[0] += e[0], na[1] += e[1], na[2] += e[2];
    nb[0] += e[0], nb[1] += e[1], nb[2] += e[2];
    nc[0] += e[0], nc[1] += e[1], nc[2] += e[2];
    weight[a] += area;
    weight[b] += area;
    weight[c] += area;
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
