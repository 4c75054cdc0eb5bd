#include "engine/geometry.hpp"

#include <limits>

#include <algorithm>
#include <cmath>

namespace vdm {

double enclosed_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin) {
  double six_v = 0.0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const Vec3 a = x.row(tris(k, 0)).transpose() - origin;
    const Vec3 b = x.row(tris(k, 1)).transpose() - origin;
    const Vec3 c = x.row(tris(k, 2)).transpose() - origin;
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

double surface_area(const NodeMat& x, const TriMat& tris) {
  double area = 0.0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const Vec3 a = x.row(tris(k, 0));
    const Vec3 b = x.row(tris(k, 1));
    const Vec3 c = x.row(tris(k, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

void distributed_area_vectors(const NodeMat& x, const TriMat& tris, NodeMat& area_vectors) {
  area_vectors.setZero();
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const int ia = tris(k, 0), ib = tris(k, 1), ic = tris(k, 2);
    const Vec3 a = x.row(ia);
    const Vec3 s = (Vec3(x.row(ib)) - a).cross(Vec3(x.row(ic)) - a) / 6.0;  // S_k / 3
    area_vectors.row(ia) += s.transpose();
    area_vectors.row(ib) += s.transpose();
    area_vectors.row(ic) += s.transpose();
  }
}

void distributed_volumes(const NodeMat& area_vectors, double volume, Vec& volumes,
                         double min_fraction) {
  const Eigen::Index n = area_vectors.rows();
  double total = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) total += area_vectors.row(i).norm();
  const double floor_area = min_fraction * total / std::max<Eigen::Index>(n, 1);
  double floored_total = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    volumes[i] = std::max(area_vectors.row(i).norm(), floor_area);
    floored_total += volumes[i];
  }
  const double scale = floored_total > 0.0 ? volume / floored_total : 0.0;
  for (Eigen::Index i = 0; i < n; ++i) volumes[i] *= scale;
}

int nearest_node(const NodeMat& x, const Vec3& p) {
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double di = (x.row(i).transpose() - p).squaredNorm();
    if (di < d) {
      d = di;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace vdm
