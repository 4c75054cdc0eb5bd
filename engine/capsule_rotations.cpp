#include "engine/capsule_rotations.hpp"

#include <cmath>

namespace vdm {
namespace {

using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

// The rotation R maximising trace(Rᵀ S) (the polar part of S when det S > 0), by turning R
// about ω = Σ_k R_k × S_k / |Σ_k R_k · S_k| (columns k) until the turn is tiny: each turn is
// a Newton-like step on the angle (Müller et al., "A robust method to extract the rotational
// part of deformations", 2016).
Quat polar_rotation(const Mat3& S) {
  Quat q = Quat::Identity();
  for (int it = 0; it < 30; ++it) {
    const Mat3 R = q.toRotationMatrix();
    const Eigen::Vector3d omega_raw = R.col(0).cross(S.col(0)) + R.col(1).cross(S.col(1)) + R.col(2).cross(S.col(2));
    const double scale = std::abs(R.col(0).dot(S.col(0)) + R.col(1).dot(S.col(1)) + R.col(2).dot(S.col(2))) + 1e-300;
    const Eigen::Vector3d omega = omega_raw / scale;
    const double angle = omega.norm();
    if (!(angle > 1e-10)) break;
    q = Quat(Eigen::AngleAxisd(angle, omega / angle)) * q;
    q.normalize();
  }
  return q;
}

}  // namespace

void fit_capsule_rotations(const TissueModel& m, const NodeMat& x, NodeRotations& rotations) {
  const NodeMat& X = m.rest.positions;
  const int* begin = m.neighbours.begin.data();
  const NeighbourLists::Entry* list = m.neighbours.entries.data();
  // The membrane's weights alone (T c_e with bending): the bending term's pairs (two edges
  // apart, weights of either sign) would make the fit ill-posed on fine meshes.
  const bool bending = m.bending_cot_weight.size() > 0;
  const double* w = bending ? m.bending_cot_weight.data() : m.capsule_weight.data();
  const double scale = bending ? m.capsule_tension : 1.0;
  for (int i = 0; i < m.n; ++i) {
    Mat3 S = Mat3::Zero();
    for (int k = begin[i]; k < begin[i + 1]; ++k) {
      const int j = list[k].node;
      const Eigen::Vector3d d = (X.row(i) - X.row(j)).transpose(), e = (x.row(i) - x.row(j)).transpose();
      S.noalias() += scale * w[list[k].edge] * e * d.transpose();
    }
    Eigen::Map<Mat3>(rotations.data() + 9 * size_t(i)) = polar_rotation(S).toRotationMatrix();
  }
}

void add_corotation_load(const TissueModel& m, const NodeRotations& rotations, NodeMat& f) {
  const NodeMat& X = m.rest.positions;
  auto rotation = [&](int i) { return Eigen::Map<const Mat3>(rotations.data() + 9 * size_t(i)); };
  const bool bending = m.bending_cot_weight.size() > 0;
  // The bending term's rotated rest curvature over the area, h_k = (R_k − I)(C X)_k / M_k, the
  // barycentric area M_k a third of node k's rest triangles' (membrane_inverse_areas).
  auto h = [&](int k) -> Eigen::Vector3d {
    return (rotation(k) - Mat3::Identity()) * m.bending_rest_laplacian.row(k).transpose() *
           (3.0 * m.membrane_inverse_areas[k]);
  };
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const int i = m.edges[e][0], j = m.edges[e][1];
    const double w = bending ? m.capsule_tension * m.bending_cot_weight[Eigen::Index(e)] : m.capsule_weight[Eigen::Index(e)];
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    if (w != 0.0) {
      const Eigen::Vector3d d = (X.row(i) - X.row(j)).transpose();
      g = w * ((0.5 * (rotation(i) + rotation(j)) - Mat3::Identity()) * d);
    }
    // Bending, ½ D Σ_k |(C x)_k − R_k (C X)_k|² / M_k: the load D C h, edge by edge.
    if (bending && m.bending_cot_weight[Eigen::Index(e)] != 0.0)
      g += m.bending_modulus * m.bending_cot_weight[Eigen::Index(e)] * (h(i) - h(j));
    f.row(i) += g.transpose();
    f.row(j) -= g.transpose();
  }
}

}  // namespace vdm
