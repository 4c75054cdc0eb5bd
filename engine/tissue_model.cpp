#include "engine/tissue_model.hpp"

#include <cmath>
#include <sstream>

#include "engine/capsule_bending.hpp"
#include "engine/cotangent_laplacian.hpp"
#include "engine/geometry.hpp"
#include "engine/membrane_frames.hpp"
#include "engine/mesh_topology.hpp"

namespace vdm {

TissueDef default_tissue(SurfaceMesh mesh) {
  TissueDef def;
  def.mesh = std::move(mesh);
  return def;
}

bool build_tissue_model(const TissueDef& def, TissueModel& m, std::string& error) {
  std::ostringstream err;
  const int n = def.mesh.node_count();
  if (n < 4 || def.mesh.triangle_count() < 4) {
    error = "the organ surface needs at least 4 nodes and 4 triangles";
    return false;
  }
  const bool per_node = def.bulk_modulus.rows() > 0;
  if (per_node && def.bulk_modulus.rows() != n) {
    err << "bulk_modulus has " << def.bulk_modulus.rows() << " rows for " << n << " nodes";
    error = err.str();
    return false;
  }
  if (def.fixed.rows() != 0 && def.fixed.rows() != n) {
    err << "fixed has " << def.fixed.rows() << " rows for " << n << " nodes";
    error = err.str();
    return false;
  }
  if (!(def.connectivity_modulus >= 0) || !std::isfinite(def.connectivity_modulus)) {
    error = "connectivity_modulus must be finite and >= 0";
    return false;
  }
  if (!(def.bending_modulus >= 0) || !std::isfinite(def.bending_modulus)) {
    error = "bending_modulus must be finite and >= 0";
    return false;
  }
  if (def.bending_modulus > 0 && def.capsule == CapsuleForm::paper) {
    error = "bending_modulus needs a membrane capsule (membrane or corotational), not the paper's";
    return false;
  }
  if (!(def.axis_stiffness_floor >= 0 && def.axis_stiffness_floor <= 1)) {
    error = "axis_stiffness_floor must be in [0, 1]";
    return false;
  }
  if (!(def.density > 0) || !std::isfinite(def.density)) {
    error = "density must be finite and > 0";
    return false;
  }
  if (!(def.dt > 0) || !std::isfinite(def.dt)) {
    error = "dt must be finite and > 0";
    return false;
  }
  if (!def.gravity.allFinite()) {
    error = "gravity must be finite";
    return false;
  }
  const SolverSettings& s = def.solver;
  if (!(s.tolerance > 0 && s.tolerance < 1) || s.max_iterations < 1 || s.refresh_every < 1 ||
      s.nonlinear_iterations < 1 || !(s.nonlinear_tolerance >= 0)) {
    error = "solver settings out of range (tolerance in (0,1), max_iterations >= 1, "
            "refresh_every >= 1, nonlinear_iterations >= 1)";
    return false;
  }

  m = TissueModel();
  m.rest = def.mesh;
  m.n = n;
  m.capsule = def.capsule;
  CotangentWeights cot;
  if (m.capsule != CapsuleForm::paper) {
    cot = cotangent_weights(def.mesh.positions, def.mesh.triangles, def.capsule_delaunay);
    m.edges = cot.edges;
    m.capsule_weight.resize(Eigen::Index(m.edges.size()));
    for (size_t e = 0; e < m.edges.size(); ++e) m.capsule_weight[Eigen::Index(e)] = cot.weights[e];
  } else {
    m.edges = unique_edges(def.mesh.triangles);
  }
  m.origin = def.mesh.positions.colwise().mean().transpose();
  m.rest_volume = enclosed_volume(def.mesh.positions, def.mesh.triangles, m.origin);
  m.rest_area = surface_area(def.mesh.positions, def.mesh.triangles);
  m.size = (def.mesh.positions.colwise().maxCoeff() - def.mesh.positions.colwise().minCoeff()).norm();
  if (!(m.rest_volume > 0)) {
    error = "the organ surface encloses no positive volume (not closed, or inward)";
    return false;
  }
  m.bulk.resize(n, 3);
  m.infinite = FlagMat::Zero(n, 3);
  m.held = def.fixed.rows() ? def.fixed : FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) {
      const double b = per_node ? def.bulk_modulus(i, d) : def.bulk;
      if (std::isinf(b) && b > 0) {
        m.bulk(i, d) = 0.0;
        m.infinite(i, d) = 1;
        m.held(i, d) = 1;
      } else if (!(b > 0) || !std::isfinite(b)) {
        err << "bulk modulus of node " << i << " axis " << "xyz"[d] << " is " << b
            << "; it must be > 0 (or inf)";
        error = err.str();
        return false;
      } else {
        m.bulk(i, d) = b;
      }
    }
  for (int i = 0; i < n; ++i)
    if (m.infinite.row(i).any()) m.infinite_nodes.push_back(i);
  m.connectivity_modulus = def.connectivity_modulus;
  if (m.membrane_capsule()) {
    m.capsule_tension = def.connectivity_modulus * m.rest_volume / m.rest_area;
    m.membrane_frames = membrane_frames(def.mesh);
    m.membrane_inverse_areas = membrane_inverse_areas(def.mesh, m.membrane_frames);
    m.capsule_weight *= m.capsule_tension;
    if (def.bending_modulus > 0) {
      // The barycentric areas: a third of each node's rest triangles'.
      const Vec area = (3.0 * m.membrane_inverse_areas).cwiseInverse();
      CapsulePairs pairs = capsule_bending_pairs(m.edges, cot.weights, area, def.bending_modulus);
      m.edges = std::move(pairs.edges);
      const Eigen::Index count = Eigen::Index(m.edges.size());
      m.bending_modulus = def.bending_modulus;
      m.bending_cot_weight = Eigen::Map<const Vec>(pairs.cot.data(), count);
      m.capsule_weight = m.capsule_tension * m.bending_cot_weight + Eigen::Map<const Vec>(pairs.bending.data(), count);
      m.bending_rest_laplacian = NodeMat::Zero(n, 3);
      for (Eigen::Index e = 0; e < count; ++e) {
        const int i = m.edges[size_t(e)][0], j = m.edges[size_t(e)][1];
        const auto d = m.bending_cot_weight[e] * (def.mesh.positions.row(i) - def.mesh.positions.row(j));
        m.bending_rest_laplacian.row(i) += d;
        m.bending_rest_laplacian.row(j) -= d;
      }
    }
    m.capsule_diagonal = Vec::Zero(n);
    for (size_t e = 0; e < m.edges.size(); ++e) {
      m.capsule_diagonal[m.edges[e][0]] += m.capsule_weight[Eigen::Index(e)];
      m.capsule_diagonal[m.edges[e][1]] += m.capsule_weight[Eigen::Index(e)];
    }
  }
  m.axis_stiffness_floor = def.axis_stiffness_floor;
  m.density = def.density;
  m.gravity = def.gravity;
  m.use_gravity = def.use_gravity;
  m.volume_constraint = def.volume_constraint;
  m.use_inertia = def.use_inertia;
  m.compute_stress = def.compute_stress;
  m.damping = def.damping;
  m.dt = def.dt;
  m.solver = def.solver;
  m.pattern = build_stiffness_pattern(n, m.edges);
  m.neighbours = build_neighbour_lists(n, m.edges);
  return true;
}

}  // namespace vdm
