// What every solver does with an AxisSystem (linear_solver.hpp): the eliminated matrices, their
// mean diagonal, the pressure that meets the volume row.
#include <algorithm>
#include <cmath>

#include "engine/linear_solver.hpp"
#include "engine/stiffness.hpp"

namespace vdm {

void eliminate_constraints(const AxisSystem& system, std::array<SpMat, 3>& K_masked) {
  for (int d = 0; d < 3; ++d)
    mask_constrained((*system.K)[size_t(d)], system.mask->col(d).data(), K_masked[size_t(d)],
                     system.springs ? system.springs->col(d).data() : nullptr);
}

double eliminated_mean_diagonal(const AxisSystem& system, const std::vector<int>& diagonal) {
  double sum = 0.0;
  const size_t n = diagonal.size();
  for (int d = 0; d < 3; ++d) {
    const double* v = (*system.K)[size_t(d)].valuePtr();
    const std::uint8_t* mask = system.mask->col(d).data();
    const double* k = system.springs ? system.springs->col(d).data() : nullptr;
    double axis = 0.0;  // per axis, then summed: as the solvers have always added it up
    for (size_t i = 0; i < n; ++i) axis += mask[i] ? 1.0 : std::abs(v[diagonal[i]] + (k ? k[i] : 0.0));
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
