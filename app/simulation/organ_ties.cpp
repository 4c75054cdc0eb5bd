#include "app/simulation/organ_ties.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/geometry.hpp"

namespace vdmsim {

double attachment_stiffness(const SceneDef& scene, const AttachmentDef& a) {
  if (a.stiffness > 0) return a.stiffness;
  const double E = std::min(scene.organs[static_cast<size_t>(a.first)].young_modulus,
                            scene.organs[static_cast<size_t>(a.second)].young_modulus);
  return E / a.within;
}

std::vector<vdm::OrganTie> organ_ties(const PreparedScene& ps, std::vector<int>* per_attachment) {
  std::vector<vdm::OrganTie> ties;
  if (per_attachment) per_attachment->clear();
  for (const AttachmentDef& a : ps.scene.attachments) {
    const size_t before = ties.size();
    const vdm::NodeMat& xa = ps.organs[static_cast<size_t>(a.first)].model.rest.positions;
    const vdm::TriMat& ta = ps.organs[static_cast<size_t>(a.first)].model.rest.triangles;
    const vdm::NodeMat& xb = ps.organs[static_cast<size_t>(a.second)].model.rest.positions;
    const vdm::TriMat& tb = ps.organs[static_cast<size_t>(a.second)].model.rest.triangles;
    // Each node's share of its surface's area: a third of its triangles'.
    std::vector<double> area(static_cast<size_t>(xa.rows()), 0.0);
    for (Eigen::Index f = 0; f < ta.rows(); ++f) {
      const vdm::Vec3 p = xa.row(ta(f, 0)), q = xa.row(ta(f, 1)), r = xa.row(ta(f, 2));
      const double third = (q - p).cross(r - p).norm() / 6.0;
      for (int v = 0; v < 3; ++v) area[static_cast<size_t>(ta(f, v))] += third;
    }
    // The second surface's triangles' boxes, grown by `within`: a node outside a box is not
    // within reach of its triangle.
    std::vector<vdm::Vec3> lo(static_cast<size_t>(tb.rows())), hi(static_cast<size_t>(tb.rows()));
    for (Eigen::Index f = 0; f < tb.rows(); ++f) {
      vdm::Vec3 l = xb.row(tb(f, 0)).transpose(), h = l;
      for (int v = 1; v < 3; ++v) {
        l = l.cwiseMin(xb.row(tb(f, v)).transpose());
        h = h.cwiseMax(xb.row(tb(f, v)).transpose());
      }
      lo[static_cast<size_t>(f)] = l.array() - a.within;
      hi[static_cast<size_t>(f)] = h.array() + a.within;
    }
    const double k_area = attachment_stiffness(ps.scene, a);
    for (Eigen::Index i = 0; i < xa.rows(); ++i) {
      const vdm::Vec3 p = xa.row(i).transpose();
      double best = a.within * a.within;
      vdm::OrganTie tie;
      bool found = false;
      for (Eigen::Index f = 0; f < tb.rows(); ++f) {
        const size_t fs = static_cast<size_t>(f);
        if ((p.array() < lo[fs].array()).any() || (p.array() > hi[fs].array()).any()) continue;
        const vdm::Vec3 A = xb.row(tb(f, 0)), B = xb.row(tb(f, 1)), C = xb.row(tb(f, 2));
        const vdm::Vec3 w = vdm::closest_barycentric(p, A, B, C);
        const vdm::Vec3 q = w.x() * A + w.y() * B + w.z() * C;
        const double d = (p - q).squaredNorm();
        if (d > best) continue;
        best = d;
        found = true;
        for (int v = 0; v < 3; ++v) {
          tie.corner[v] = tb(f, v);
          tie.weight[v] = w[v];
        }
        tie.offset = p - q;
      }
      if (!found) continue;
      tie.owner = a.first;
      tie.node = static_cast<int>(i);
      tie.other = a.second;
      tie.stiffness = k_area * area[static_cast<size_t>(i)];
      tie.tear = a.tear_force;
      if (tie.stiffness > 0) ties.push_back(tie);
    }
    if (per_attachment) per_attachment->push_back(static_cast<int>(ties.size() - before));
  }
  return ties;
}

}  // namespace vdmsim
