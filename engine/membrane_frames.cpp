#include "engine/membrane_frames.hpp"

namespace vdm {

std::vector<double> membrane_frames(const SurfaceMesh& rest) {
  const size_t blocks = (size_t(rest.triangle_count()) + 3) / 4;
  std::vector<double> out(blocks * kMembraneFrameBlock, 0.0);  // padding lanes: area 0
  for (int t = 0; t < rest.triangle_count(); ++t) {
    const Vec3 a = rest.positions.row(rest.triangles(t, 0)), b = rest.positions.row(rest.triangles(t, 1)),
               c = rest.positions.row(rest.triangles(t, 2));
    const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
    double* f = out.data() + size_t(t / 4) * kMembraneFrameBlock + size_t(t % 4);  // field k at f[4 k]
    const double area2 = n.norm();
    if (!(area2 > 0.0) || !(ab.norm() > 0.0)) continue;  // degenerate: no strain (the mesh check refuses these)
    const Vec3 e1 = ab.normalized(), e2 = n.cross(ab).normalized();
    // D in the basis: columns (ab.e1, ab.e2) = (|ab|, 0) and (ac.e1, ac.e2); D⁻¹ is upper
    // triangular too.
    const double d00 = ab.dot(e1), d01 = ac.dot(e1), d11 = ac.dot(e2);
    const double det = d00 * d11;
    for (int k = 0; k < 3; ++k) {
      f[4 * k] = e1[k];
      f[4 * (3 + k)] = e2[k];
    }
    f[4 * 6] = d11 / det;
    f[4 * 7] = -d01 / det;
    f[4 * 8] = d00 / det;
    f[4 * 9] = 0.5 * area2;
  }
  return out;
}

Vec membrane_inverse_areas(const SurfaceMesh& rest, const std::vector<double>& frames) {
  Vec area = Vec::Zero(rest.positions.rows());
  for (int t = 0; t < rest.triangle_count(); ++t)
    for (int j = 0; j < 3; ++j)
      area[rest.triangles(t, j)] += frames[size_t(t / 4) * kMembraneFrameBlock + 4 * 9 + size_t(t % 4)];
  for (Eigen::Index i = 0; i < area.size(); ++i) area[i] = area[i] > 0.0 ? 1.0 / area[i] : 0.0;
  return area;
}

}  // namespace vdm
