#include "app/scene/scan_like_organ.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "app/scene/organ_generator.hpp"
#include "engine/mesh_topology.hpp"

namespace vdmsim {
namespace {

vdm::NodeMat node_normals(const vdm::SurfaceMesh& m) {
  vdm::NodeMat n = vdm::NodeMat::Zero(m.node_count(), 3);
  for (int k = 0; k < m.triangle_count(); ++k) {
    const vdm::Vec3 a = m.positions.row(m.triangles(k, 0)), b = m.positions.row(m.triangles(k, 1)),
                    c = m.positions.row(m.triangles(k, 2));
    const vdm::Vec3 area = (b - a).cross(c - a);
    for (int j = 0; j < 3; ++j) n.row(m.triangles(k, j)) += area.transpose();
  }
  n.rowwise().normalize();
  return n;
}

// Pushes a round patch of the thin left lobe's top straight down, through the underside.
void push_fold(vdm::SurfaceMesh& m) {
  const vdm::NodeMat& x = m.positions;
  int top = -1;
  for (int i = 0; i < m.node_count(); ++i)
    if (x(i, 0) < -0.08 && x(i, 0) > -0.1 && std::abs(x(i, 1)) < 0.015 && (top < 0 || x(i, 2) > x(top, 2))) top = i;
  if (top < 0) return;
  const vdm::Vec3 p0 = x.row(top);
  double bottom = p0.z();
  for (int i = 0; i < m.node_count(); ++i)
    if ((x.row(i).head<2>() - p0.head<2>().transpose()).norm() < 0.004) bottom = std::min(bottom, x(i, 2));
  const double depth = p0.z() - bottom + 0.006, radius = 0.012;
  for (int i = 0; i < m.node_count(); ++i) {
    const double r = (m.positions.row(i).transpose() - p0).norm();
    if (r >= radius || m.positions(i, 2) < 0.5 * (p0.z() + bottom)) continue;
    const double w = 1 - (r / radius) * (r / radius);
    m.positions(i, 2) -= depth * w * w;
  }
}

}  // namespace

vdm::SurfaceMesh make_scan_like_liver(const ScanLikeOptions& opt) {
  vdm::SurfaceMesh m = make_liver_mesh(opt.level);
  std::mt19937 rng(opt.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  if (opt.fold) push_fold(m);
  const vdm::NodeMat normals = node_normals(m);
  for (int i = 0; i < m.node_count(); ++i) m.positions.row(i) += 0.001 * opt.jitter_mm * unit(rng) * normals.row(i);

  // The crop: every triangle with a node beyond the cut goes (an open, flat-edged hole); two
  // single triangles elsewhere go too (small holes); a few are written twice.
  const double cut = m.positions.col(0).maxCoeff() - 0.001 * opt.crop_mm;
  std::vector<Eigen::Matrix<int, 1, 3>> kept;
  for (int k = 0; k < m.triangle_count(); ++k) {
    bool beyond = false;
    for (int j = 0; j < 3; ++j) beyond = beyond || m.positions(m.triangles(k, j), 0) > cut;
    if (beyond || k == m.triangle_count() / 3 || k == m.triangle_count() / 2) continue;
    kept.push_back(m.triangles.row(k));
    if (k % 997 == 0) kept.push_back(m.triangles.row(k));
  }
  vdm::SurfaceMesh out;
  out.triangles.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t k = 0; k < kept.size(); ++k) out.triangles.row(static_cast<Eigen::Index>(k)) = kept[k];
  out.positions = 1000.0 * m.positions;
  out.positions.rowwise() += opt.scanner_offset_mm.transpose();
  vdm::drop_unreferenced_nodes(out);
  return out;
}

}  // namespace vdmsim
