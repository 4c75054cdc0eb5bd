// What every solver does with an AxisSystem (linear_solver.hpp): the eliminated matrices, their
// mean diagonal, the pressure that meets the volume row.
#include <algorithm>
#include <cmath>

#include "engine/linear_solver.hpp"

namespace vdm {

void eliminate_constraints(const AxisSystem& system, std::array<SpMat, 3>& K_masked) {
  const StiffnessPattern& p = *system.pattern;
  const AxisStiffness& K = *system.K;
  for (int d = 0; d < 3; ++d) {
    const std::uint8_t* mask = system.mask->col(d).data();
    const double* k = system.springs ? system.springs->col(d).data() : nullptr;
    double* v = K_masked[size_t(d)].valuePtr();
    for (size_t e = 0; e < p.edges.size(); ++e) {
      const bool held = mask[p.edges[e][0]] || mask[p.edges[e][1]];
      v[p.edge_slot[e][0]] = v[p.edge_slot[e][1]] = held ? 0.0 : -K.weight[Eigen::Index(e)];
    }
    const double* diag = K.diagonal.col(d).data();
    for (size_t i = 0; i < p.diagonal.size(); ++i) v[p.diagonal[i]] = mask[i] ? 1.0 : diag[i] + (k ? k[i] : 0.0);
  }
}

double eliminated_mean_diagonal(const AxisSystem& system, const NodeMat* a, NodeMat* a_free) {
  double sum = 0.0;
  const Eigen::Index n = system.K->diagonal.rows();
  for (int d = 0; d < 3; ++d) {
    const double* diag = system.K->diagonal.col(d).data();
    const std::uint8_t* mask = system.mask->col(d).data();
    const double* k = system.springs ? system.springs->col(d).data() : nullptr;
    double axis = 0.0;  // per axis, then summed: as the solvers have always added it up
    const double* ad = a_free ? a->col(d).data() : nullptr;
    double* fd = a_free ? a_free->col(d).data() : nullptr;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (fd) fd[i] = mask[i] ? 0.0 : ad[i];
      axis += mask[i] ? 1.0 : std::abs(diag[i] + (k ? k[i] : 0.0));
    }
    sum += axis;
  }
  return n > 0 ? sum / double(3 * n) : 0.0;
}

double pressure_scale(double mean_diagonal, const NodeMat& a) {
  const double mean_a = a.cwiseAbs().sum() / std::max<double>(1.0, double(a.size()));
  if (!(mean_a > 0) || !(mean_diagonal > 0)) return 1.0;
  return mean_diagonal / mean_a;
}

double pressure_for_volume(const NodeMat& a, const NodeMat& r, const NodeMat& s, double c) {
  double as = 0.0, ar = 0.0;
  for (int d = 0; d < 3; ++d) {
    as += a.col(d).dot(s.col(d));
    ar += a.col(d).dot(r.col(d));
  }
  // a.s > 0 whenever some node can move; otherwise the fluid has nothing to push.
  return (as > 0.0 && std::isfinite(as)) ? (c - ar) / as : 0.0;
}

}  // namespace vdm
