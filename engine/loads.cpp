#include "engine/loads.hpp"

namespace vdm {

void add_hydrostatic_loads(const TissueModel& m, const NodeMat& x, const NodeMat& A, Vec& height,
                           NodeMat& force) {
  const double g = m.gravity.norm();
  if (!(g > 0)) return;
  const Vec3 dir = m.gravity / g;
  height.noalias() = x * dir;  // coordinate along gravity: larger = deeper
  const double top = height.minCoeff();
  for (int i = 0; i < m.n; ++i) force.row(i) += m.density * g * (height[i] - top) * A.row(i);
}

}  // namespace vdm
