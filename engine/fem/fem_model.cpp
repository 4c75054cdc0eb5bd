#include "engine/fem/fem_model.hpp"

#include <cmath>

namespace vdm::fem {

double lame_mu(double E, double nu) { return E / (2 * (1 + nu)); }
double lame_lambda(double E, double nu) { return E * nu / ((1 + nu) * (1 - 2 * nu)); }

bool build_fem_model(const FemDef& def, FemModel& m, std::string& error) {
  if (!(def.young_modulus > 0) || !std::isfinite(def.young_modulus))
    return error = "young_modulus must be > 0 (Pa)", false;
  if (!(def.poisson_ratio >= 0 && def.poisson_ratio < 0.5))
    return error = "poisson_ratio must be in [0, 0.5)", false;
  m.mesh = def.mesh;
  if (!check_tet_mesh(m.mesh, error)) return false;
  m.n = m.mesh.node_count();
  m.ns = m.mesh.surface_nodes;
  m.tets = m.mesh.tet_count();
  m.young_modulus = def.young_modulus;
  m.poisson_ratio = def.poisson_ratio;
  m.mu = lame_mu(def.young_modulus, def.poisson_ratio);
  m.lambda = lame_lambda(def.young_modulus, def.poisson_ratio);
  m.settings = def.settings;
  const NodeMat& X = m.mesh.positions;
  m.grad.resize(static_cast<size_t>(m.tets));
  m.tet_volume.resize(m.tets);
  Vec node_volume = Vec::Zero(m.n);
  for (int t = 0; t < m.tets; ++t) {
    Eigen::Matrix3d Dm;
    for (int c = 0; c < 3; ++c) Dm.col(c) = (X.row(m.mesh.tets(t, c + 1)) - X.row(m.mesh.tets(t, 0))).transpose();
    const Eigen::Matrix3d Dinv = Dm.inverse();
    // N_q for q = 1..3 has gradient row q-1 of Dm^{-1}; N_0 = 1 - sum.
    Eigen::Matrix<double, 4, 3> G;
    G.bottomRows<3>() = Dinv;
    G.row(0) = -Dinv.colwise().sum();
    m.grad[static_cast<size_t>(t)] = G;
    m.tet_volume[t] = Dm.determinant() / 6.0;
    for (int q = 0; q < 4; ++q) node_volume[m.mesh.tets(t, q)] += m.tet_volume[t] / 4;
  }
  m.rest_volume = m.tet_volume.sum();
  m.size = (X.colwise().maxCoeff() - X.colwise().minCoeff()).norm();
  // Volumetric groups.
  m.group_start.assign(1, 0);
  m.group_tet.clear();
  m.group_weight.clear();
  if (m.settings.nodal_volumetric) {
    std::vector<std::vector<int>> around(static_cast<size_t>(m.n));
    for (int t = 0; t < m.tets; ++t)
      for (int q = 0; q < 4; ++q) around[static_cast<size_t>(m.mesh.tets(t, q))].push_back(t);
    m.group_volume = node_volume;
    for (int a = 0; a < m.n; ++a) {
      for (int t : around[static_cast<size_t>(a)]) {
        m.group_tet.push_back(t);
        m.group_weight.push_back(m.tet_volume[t] / 4 / node_volume[a]);
      }
      m.group_start.push_back(static_cast<int>(m.group_tet.size()));
    }
  } else {
    m.group_volume = m.tet_volume;
    for (int t = 0; t < m.tets; ++t) {
      m.group_tet.push_back(t);
      m.group_weight.push_back(1.0);
      m.group_start.push_back(t + 1);
    }
  }
  m.fixed = FlagMat::Zero(m.n, 3);
  if (def.fixed.rows() == m.ns) m.fixed.topRows(m.ns) = def.fixed;
  else if (def.fixed.rows() != 0) return error = "fixed must have one row per surface node", false;
  m.gravity_force.resize(0, 3);
  if (def.use_gravity) {
    m.gravity_force.resize(m.n, 3);
    for (int a = 0; a < m.n; ++a) m.gravity_force.row(a) = def.density * node_volume[a] * def.gravity.transpose();
  }
  return true;
}

}  // namespace vdm::fem
