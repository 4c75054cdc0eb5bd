#include "engine/stress.hpp"

#include <cmath>

namespace vdm {

void compute_strain_stress(const TissueModel& m, SimState& s) {
  const NodeMat& A = s.area_vectors;
  const Vec& Vi = s.node_volumes;
  // dV_i^d = A_i^d u_i^d, kept in `strain` until the division by V_i below.
  s.strain = A.cwiseProduct(s.u);
  // Connectivity: sum_j B_ij (dV_i^d - dV_j^d), summed per node in `stress` first.
  s.stress.setZero();
  const double bc = m.connectivity_modulus;
  if (bc != 0.0) {  // one pass over the edges for the three axes
    const double* dv[3] = {s.strain.col(0).data(), s.strain.col(1).data(), s.strain.col(2).data()};
    double* sum[3] = {s.stress.col(0).data(), s.stress.col(1).data(), s.stress.col(2).data()};
    for (const auto& e : m.edges)
      for (int d = 0; d < 3; ++d) {
        const double t = bc * (dv[d][e[0]] - dv[d][e[1]]);
        sum[d][e[0]] += t;
        sum[d][e[1]] -= t;
      }
  }
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      const double tension = s.stress(i, d) / Vi[i];
      if (m.infinite(i, d)) {
        const double tiny = 1e-9 * A.row(i).norm();
        s.strain(i, d) = 0.0;
        s.stress(i, d) = (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0) + tension;
      } else {
        s.strain(i, d) /= Vi[i];
        s.stress(i, d) = m.bulk(i, d) * s.strain(i, d) + tension;
      }
    }
}

}  // namespace vdm
