#include "engine/stress.hpp"

#include <cmath>

#include "engine/membrane_strain.hpp"
#include "engine/simd2.hpp"

namespace vdm {

void compute_strain_stress(const TissueModel& m, SimState& s, double* dv) {
  const NodeMat& A = s.area_vectors;
  const int n = m.n;
  // dV_i^d = A_i^d u_i^d, node by node (3 per row): a neighbour's three are one load pair
  // and one load in the gather below, not three loads from three columns.
  for (int d = 0; d < 3; ++d) {
    const double* a = A.col(d).data();
    const double* u = s.u.col(d).data();
    for (int i = 0; i < n; ++i) dv[3 * i + d] = a[i] * u[i];
  }
  // A membrane capsule's stress comes from its strain, added at the end: no eq (6) tension.
  const double bc = m.membrane_capsule() ? 0.0 : m.connectivity_modulus;
  const int* outer = m.pattern.matrix.outerIndexPtr();
  const int* inner = m.pattern.matrix.innerIndexPtr();
  // Connectivity: sum_j B_ij (dV_i^d - dV_j^d) = B_c sum_j (dV_i^d - dV_j^d), gathered over
  // the pattern's column i (K is symmetric: its rows are its columns; the diagonal entry
  // adds dV_i - dV_i = 0), x and y as an SSE2 pair, z alone: each axis summed in the order
  // of a scalar loop of its own.
  auto tension_sums = [&](int i, double sum[3]) {
    simd::V2 xy = {0.0, 0.0};
    double z = 0.0;
    if (bc != 0.0) {
      const simd::V2 own_xy = simd::load2(dv + 3 * i);
      const double own_z = dv[3 * i + 2];
      for (int k = outer[i]; k < outer[i + 1]; ++k) {
        const int j = inner[k];
        xy += own_xy - simd::load2(dv + 3 * j);
        z += own_z - dv[3 * j + 2];
      }
    }
    sum[0] = xy[0];
    sum[1] = xy[1];
    sum[2] = z;
  };
  double* strain[3] = {s.strain.col(0).data(), s.strain.col(1).data(), s.strain.col(2).data()};
  double* sigma[3] = {s.stress.col(0).data(), s.stress.col(1).data(), s.stress.col(2).data()};
  const double* bulk[3] = {m.bulk.col(0).data(), m.bulk.col(1).data(), m.bulk.col(2).data()};
  const double* vol = s.node_volumes.data();
  // Strain and stress of node i at once (one division by V_i for the three axes), as for a
  // finite B on every entry; the few infinite ones are redone below.
  for (int i = 0; i < n; ++i) {
    double sum[3];
    tension_sums(i, sum);
    const double inv_v = 1.0 / vol[i];
    for (int d = 0; d < 3; ++d) {
      const double eps = dv[3 * i + d] * inv_v;
      strain[d][i] = eps;
      sigma[d][i] = bulk[d][i] * eps + bc * sum[d] * inv_v;
    }
  }
  // An infinite B_i^d: no strain (u_i^d = 0 is a constraint), and the bulk term is the
  // constraint force over the patch area, -reaction_i^d / A_i^d.
  for (const int i : m.infinite_nodes) {
    double sum[3];
    tension_sums(i, sum);
    const double inv_v = 1.0 / vol[i];
    const double tiny = 1e-9 * A.row(i).norm();
    for (int d = 0; d < 3; ++d) {
      if (!m.infinite(i, d)) continue;
      strain[d][i] = 0.0;
      sigma[d][i] = (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0) + bc * sum[d] * inv_v;
    }
  }
  if (m.membrane_capsule()) add_membrane_stress(m, s, dv);
}

}  // namespace vdm
