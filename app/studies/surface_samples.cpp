#include "app/studies/surface_samples.hpp"

#include "engine/geometry.hpp"

#include <algorithm>
#include <limits>

namespace vdmsim {

SurfaceSamples::SurfaceSamples(const vdm::SurfaceMesh& rest, const vdm::NodeMat& points) {
  const vdm::NodeMat& x = rest.positions;
  const vdm::TriMat& t = rest.triangles;
  const int n = static_cast<int>(x.rows());
  // Triangles around each node.
  std::vector<std::vector<int>> around(static_cast<size_t>(n));
  for (int k = 0; k < t.rows(); ++k)
    for (int q = 0; q < 3; ++q) around[static_cast<size_t>(t(k, q))].push_back(k);
  constexpr int kNearest = 4;  // the closest point may lie on a triangle of a near, not the nearest, node
  std::vector<std::pair<double, int>> near;
  near.reserve(static_cast<size_t>(n));
  for (int s = 0; s < points.rows(); ++s) {
    const vdm::Vec3 p = points.row(s);
    near.clear();
    for (int i = 0; i < n; ++i) near.emplace_back((x.row(i).transpose() - p).squaredNorm(), i);
    const int keep = std::min(kNearest, n);
    std::partial_sort(near.begin(), near.begin() + keep, near.end());
    double best = std::numeric_limits<double>::infinity();
    std::array<int, 3> best_tri{0, 0, 0};
    vdm::Vec3 best_w(1, 0, 0);
    for (int j = 0; j < keep; ++j)
      for (int k : around[static_cast<size_t>(near[static_cast<size_t>(j)].second)]) {
        const vdm::Vec3 a = x.row(t(k, 0)), b = x.row(t(k, 1)), c = x.row(t(k, 2));
        const vdm::Vec3 w = vdm::closest_barycentric(p, a, b, c);
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
