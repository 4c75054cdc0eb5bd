#include "engine/stress.hpp"

#include <cmath>

namespace vdm {

void compute_strain_stress(const TissueModel& m, SimState& s) {
  const NodeMat& A = s.area_vectors;
  const Vec& Vi = s.node_volumes;
  // dV_i^d = A_i^d u_i^d, kept in `strain` until the division by V_i below.
  s.strain = A.cwiseProduct(s.u);
  // Connectivity: sum_j B_ij (dV_i^d - dV_j^d) = B_c sum_j (dV_i^d - dV_j^d), the sums per
  // node in `stress` first (one pass over the edges for the three axes).
  s.stress.setZero();
  const double bc = m.connectivity_modulus;
  double* dv[3] = {s.strain.col(0).data(), s.strain.col(1).data(), s.strain.col(2).data()};
  double* sum[3] = {s.stress.col(0).data(), s.stress.col(1).data(), s.stress.col(2).data()};
  if (bc != 0.0)
    for (const auto& e : m.edges)
      for (int d = 0; d < 3; ++d) {
        const double t = dv[d][e[0]] - dv[d][e[1]];
        sum[d][e[0]] += t;
        sum[d][e[1]] -= t;
      }
  // Per node: one division (by V_i) for the three axes.
  for (int i = 0; i < m.n; ++i) {
    const double inv_v = 1.0 / Vi[i];
    for (int d = 0; d < 3; ++d) {
      const double tension = bc * sum[d][i] * inv_v;
      if (m.infinite(i, d)) {
        const double tiny = 1e-9 * A.row(i).norm();
        dv[d][i] = 0.0;
        sum[d][i] = (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0) + tension;
      } else {
        dv[d][i] *= inv_v;
        sum[d][i] = m.bulk(i, d) * dv[d][i] + tension;
      }
    }
  }
}

}  // namespace vdm
