#include "app/surface_samples.hpp"

#include <algorithm>
#include <limits>

namespace vdmsim {

vdm::Vec3 closest_barycentric(const vdm::Vec3& p, const vdm::Vec3& a, const vdm::Vec3& b, const vdm::Vec3& c) {
  // Regions of the triangle's plane (vertex, edge, face), after Ericson's Real-Time Collision
  // Detection, section 5.1.5.
  const vdm::Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const vdm::Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const vdm::Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

SurfaceSamples::SurfaceSamples(const vdm::SurfaceMesh& rest, const vdm::NodeMat& points) {
  const vdm::NodeMat& x = rest.positions;
  const vdm::TriMat& t = rest.triangles;
  const int n = static_cast<int>(x.rows());
  // Triangles around each node.
  std::vector<std::vector<int>> around(static_cast<size_t>(n));
  for (int k = 0; k < t.rows(); ++k)
    for (int q = 0; q < 3; ++q) around[static_cast<size_t>(t(k, q))].push_back(k);
  constexpr int kNearest = 4;  // the closest point may lie on a triangle of a near, not the nearest, node
  for (int s = 0; s < points.rows(); ++s) {
    const vdm::Vec3 p = points.row(s);
    std::vector<std::pair<double, int>> near;
    near.reserve(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) near.emplace_back((x.row(i).transpose() - p).squaredNorm(), i);
    const int keep = std::min(kNearest, n);
    std::partial_sort(near.begin(), near.begin() + keep, near.end());
    double best = std::numeric_limits<double>::infinity();
    std::array<int, 3> best_tri{0, 0, 0};
    vdm::Vec3 best_w(1, 0, 0);
    for (int j = 0; j < keep; ++j)
      for (int k : around[static_cast<size_t>(near[static_cast<size_t>(j)].second)]) {
        const vdm::Vec3 a = x.row(t(k, 0)), b = x.row(t(k, 1)), c = x.row(t(k, 2));
        const vdm::Vec3 w = closest_barycentric(p, a, b, c);
        const double d = (w[0] * a + w[1] * b + w[2] * c - p).norm();
        if (d < best) {
          best = d;
          best_tri = {t(k, 0), t(k, 1), t(k, 2)};
          best_w = w;
        }
      }
    tri_.push_back(best_tri);
    weight_.push_back(best_w);
    max_gap_ = std::max(max_gap_, best);
  }
}

void SurfaceSamples::interpolate(const vdm::NodeMat& u, vdm::NodeMat& out) const {
  out.resize(size(), 3);
  for (int s = 0; s < size(); ++s) {
    const auto& tri = tri_[static_cast<size_t>(s)];
    const vdm::Vec3& w = weight_[static_cast<size_t>(s)];
    out.row(s) = w[0] * u.row(tri[0]) + w[1] * u.row(tri[1]) + w[2] * u.row(tri[2]);
  }
}

}  // namespace vdmsim
