// The elastic core's strain and stress (engine/core/core_stress.hpp).
#include "engine/core/core_stress.hpp"

#include <cmath>

#include "engine/core/core_workspace.hpp"

namespace vdm::core {

void core_strain(const CoreModel& m, const NodeMat& v, const std::vector<Eigen::Matrix3d>& rotations, CoreStrain& out) {
  const UnitCube& cube = unit_cube();
  const size_t tets = static_cast<size_t>(6 * m.cubes.rows());
  out.tet.resize(tets);
  out.lattice.resize(static_cast<size_t>(m.ng));
  for (Eigen::Matrix3d& e : out.lattice) e.setZero();
  out.weight.setZero(m.ng);
  const double tet_volume = m.h * m.h * m.h / 6;
  for (Eigen::Index q = 0; q < m.cubes.rows(); ++q) {
    const double w = m.fill[q] * tet_volume;
    for (int t = 0; t < 6; ++t) {
      const size_t k = static_cast<size_t>(6 * q + t);
      // F = I + sum_a v_a (x) grad N_a, the unit cube's gradients over h (as tet_rotations()).
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int a = 0; a < 4; ++a) F += v.row(m.cubes(q, cube.corner[t][a])).transpose() * cube.grad[t].row(a) / m.h;
      const Eigen::Matrix3d FRt = F * rotations[k].transpose();
      Eigen::Matrix3d& e = out.tet[k];
      e = 0.5 * (FRt + FRt.transpose());
      e.diagonal().array() -= 1.0;
      for (int a = 0; a < 4; ++a) {
        const int node = m.cubes(q, cube.corner[t][a]);
        out.lattice[static_cast<size_t>(node)] += w * e;
        out.weight[node] += w;
      }
    }
  }
  for (int k = 0; k < m.ng; ++k)
    if (out.weight[k] > 0) out.lattice[static_cast<size_t>(k)] /= out.weight[k];
}

Eigen::Matrix3d surface_strain(const CoreModel& m, const CoreStrain& c, int i) {
  Eigen::Matrix3d e = Eigen::Matrix3d::Zero();
  for (int p = 0; p < 4; ++p) e += m.tie_weight(i, p) * c.lattice[static_cast<size_t>(m.tie_node(i, p))];
  return e;
}

void surface_stress(const CoreModel& m, const CoreStrain& c, double pressure, NodeMat& stress, NodeMat& strain) {
  const double E = m.young_modulus;
  for (int i = 0; i < m.ns; ++i) {
    const Eigen::Matrix3d e = surface_strain(m, c, i);
    for (int d = 0; d < 3; ++d) {
      strain(i, d) = e(d, d);
      stress(i, d) = E * e(d, d) - pressure;
    }
  }
}

void core_strain(const CoreModel& m, const CoreState& s, CoreStrain& out) { core_strain(m, s.v, s.work->rotation, out); }

void core_surface_stress(const CoreModel& m, const CoreState& s, CoreStrain& work, NodeMat& stress, NodeMat& strain) {
  core_strain(m, s, work);
  surface_stress(m, work, s.pressure, stress, strain);
}

double von_mises(const Eigen::Matrix3d& sigma) {
  Eigen::Matrix3d dev = 0.5 * (sigma + sigma.transpose());
  dev.diagonal().array() -= dev.trace() / 3;
  return std::sqrt(1.5 * dev.squaredNorm());
}

}  // namespace vdm::core
