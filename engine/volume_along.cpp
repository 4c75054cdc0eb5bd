#include "engine/volume_along.hpp"

namespace vdm {

// 6 V = sum_k (a - o) . n_k with n_k = (b - a) x (c - a), as enclosed_volume() sums it. On a
// closed surface 6 A_i sums the n_k of the triangles at node i, so 6 A(x) . d = sum_k n_k .
// (d_a + d_b + d_c): the slope needs no per-node sums (no scatter) either.
VolumeAlong volume_along(const NodeMat& x, const NodeMat& d, const FlagMat* frozen, const TriMat& tris,
                         const Vec3& origin, std::vector<double>& packed) {
  const size_t n = size_t(x.rows());
  packed.resize(6 * n);
  double* p = packed.data();
  for (size_t k = 0; k < 3; ++k) {
    const double* xc = x.col(Eigen::Index(k)).data();
    const double* dc = d.col(Eigen::Index(k)).data();
    const std::uint8_t* fc = frozen ? frozen->col(Eigen::Index(k)).data() : nullptr;
    for (size_t i = 0; i < n; ++i) {
      p[6 * i + k] = xc[i];
      p[6 * i + 3 + k] = fc && fc[i] ? 0.0 : dc[i];
    }
  }
  // Plain scalars, in enclosed_volume()'s order of operations (Eigen's cross and dot).
  const double ox = origin[0], oy = origin[1], oz = origin[2];
  double six_v = 0, six_slope = 0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const double* a = p + 6 * size_t(tris(k, 0));
    const double* b = p + 6 * size_t(tris(k, 1));
    const double* c = p + 6 * size_t(tris(k, 2));
    const double e1x = b[0] - a[0], e1y = b[1] - a[1], e1z = b[2] - a[2];
    const double e2x = c[0] - a[0], e2y = c[1] - a[1], e2z = c[2] - a[2];
    const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
    six_v += (a[0] - ox) * nx + (a[1] - oy) * ny + (a[2] - oz) * nz;
    six_slope += (a[3] + b[3] + c[3]) * nx + (a[4] + b[4] + c[4]) * ny + (a[5] + b[5] + c[5]) * nz;
  }
  return {six_v / 6.0, six_slope / 6.0};
}

}  // namespace vdm
