#include "engine/stress.hpp"

#include <cmath>

namespace vdm {

void compute_strain_stress(const TissueModel& m, SimState& s) {
  const NodeMat& A = s.area_vectors;
  const Vec& Vi = s.node_volumes;
  // dV_i^d = A_i^d u_i^d, kept in `strain` until the division by V_i below.
  s.strain = A.cwiseProduct(s.u);
  const double bc = m.connectivity_modulus;
  const double* dv[3] = {s.strain.col(0).data(), s.strain.col(1).data(), s.strain.col(2).data()};
  double* sigma[3] = {s.stress.col(0).data(), s.stress.col(1).data(), s.stress.col(2).data()};
  // Connectivity: sum_j B_ij (dV_i^d - dV_j^d) = B_c sum_j (dV_i^d - dV_j^d), gathered node
  // by node over the pattern's column i (K is symmetric: its rows are its columns; the
  // diagonal entry adds dV_i - dV_i = 0), for the three axes; the stress of node i into
  // `stress` at once. The strains are divided by V_i in a second pass: the gather reads
  // them undivided.
  const int* outer = m.pattern.matrix.outerIndexPtr();
  const int* inner = m.pattern.matrix.innerIndexPtr();
  for (int i = 0; i < m.n; ++i) {
    double sum[3] = {0.0, 0.0, 0.0};
    if (bc != 0.0)
      for (int k = outer[i]; k < outer[i + 1]; ++k) {
        const int j = inner[k];
        for (int d = 0; d < 3; ++d) sum[d] += dv[d][i] - dv[d][j];
      }
    const double inv_v = 1.0 / Vi[i];
    for (int d = 0; d < 3; ++d) {
      const double tension = bc * sum[d] * inv_v;
      if (m.infinite(i, d)) {
        const double tiny = 1e-9 * A.row(i).norm();
        sigma[d][i] = (std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0) + tension;
      } else {
        sigma[d][i] = m.bulk(i, d) * (dv[d][i] * inv_v) + tension;
      }
    }
  }
  for (int i = 0; i < m.n; ++i) {
    const double inv_v = 1.0 / Vi[i];
    for (int d = 0; d < 3; ++d) s.strain(i, d) = m.infinite(i, d) ? 0.0 : s.strain(i, d) * inv_v;
  }
}

}  // namespace vdm
