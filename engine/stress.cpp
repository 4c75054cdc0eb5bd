#include "engine/stress.hpp"

#include <cmath>

namespace vdm {

void compute_strain_stress(const TissueModel& m, SimState& s) {
  const NodeMat& A = s.area_vectors;
  const Vec& Vi = s.node_volumes;
  for (int i = 0; i < m.n; ++i) {
    const double tiny = 1e-9 * A.row(i).norm();
    for (int d = 0; d < 3; ++d) {
      const double dv = A(i, d) * s.u(i, d);
      s.strain(i, d) = dv / Vi[i];
      if (m.infinite(i, d)) {
        s.strain(i, d) = 0.0;
        s.stress(i, d) = std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0;
      } else {
        s.stress(i, d) = m.bulk(i, d) * s.strain(i, d);
      }
    }
  }
  const double bc = m.connectivity_modulus;
  if (bc == 0.0) return;
  for (const auto& e : m.edges) {
    const int i = e[0], j = e[1];
    for (int d = 0; d < 3; ++d) {
      const double t = bc * (A(i, d) * s.u(i, d) - A(j, d) * s.u(j, d));
      s.stress(i, d) += t / Vi[i];
      s.stress(j, d) -= t / Vi[j];
    }
  }
}

}  // namespace vdm
